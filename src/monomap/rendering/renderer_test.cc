#include "monomap/rendering/renderer.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <opencv2/imgproc.hpp>

#include "monomap/util/error.h"

namespace monomap {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

Camera TestCamera() {
  Camera c;
  c.width = 640;
  c.height = 480;
  c.fx = c.fy = 500;
  c.cx = 319.5;
  c.cy = 239.5;
  return c;
}

// Camera at `centre` looking at `target`; `up` is a world direction that
// appears upwards in the image.
Rigid3d LookAt(const Vector3d& centre, const Vector3d& target,
               const Vector3d& up) {
  const Vector3d z = (target - centre).normalized();
  const Vector3d y = -(up - up.dot(z) * z).normalized();
  const Vector3d x = y.cross(z);
  Eigen::Matrix3d r;
  r << x, y, z;
  return Rigid3d(Eigen::Quaterniond(r), centre);
}

// A plane through `origin` spanned by u, v with a texture whose grey value
// at plane coordinates (s, t) is `grey(s, t)` (alpha 255).
TexturedPlane MakePlane(const Vector3d& origin, const Vector3d& u,
                        const Vector3d& v, double ppm, int cols, int rows,
                        const std::function<double(double, double)>& grey) {
  TexturedPlane p;
  p.frame.origin = origin;
  p.frame.u_axis = u.normalized();
  p.frame.v_axis = v.normalized();
  p.plane.normal = p.frame.Normal();
  p.plane.offset = -p.plane.normal.dot(origin);
  p.pixels_per_meter = ppm;
  p.texture.create(rows, cols, CV_8UC4);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const double g = grey((c + 0.5) / ppm, (r + 0.5) / ppm);
      const uint8_t b = cv::saturate_cast<uint8_t>(g);
      p.texture.at<cv::Vec4b>(r, c) = cv::Vec4b(b, b, b, 255);
    }
  }
  return p;
}

double Smooth(double s, double t) {
  return 128 + 90 * std::sin(2 * M_PI * s / 0.1) * std::cos(2 * M_PI * t / 0.08);
}

// Ray through pixel (u, v) meets the plane z = z0 at world point *x and
// depth *z (along the optical axis); false if it does not (or behind).
bool CastToHorizontalPlane(const Camera& cam, const Rigid3d& world_from_cam,
                           double u, double v, double z0, Vector3d* x,
                           double* z) {
  const Vector3d d_cam((u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy, 1.0);
  const Vector3d d = world_from_cam.rotation * d_cam;
  const Vector3d c = world_from_cam.translation;
  if (std::abs(d.z()) < 1e-12) return false;
  const double lambda = (z0 - c.z()) / d.z();
  if (lambda <= 0) return false;
  *x = c + lambda * d;
  *z = lambda;
  return true;
}

TEST(RendererTest, SinglePlaneMatchesAnalyticProjection) {
  const double ppm = 500;
  const TexturedPlane plane =
      MakePlane(Vector3d(-0.4, -0.3, 0), Vector3d::UnitX(), Vector3d::UnitY(),
                ppm, 400, 300, Smooth);
  RendererOptions options;
  options.background_grey = 7;
  const Renderer renderer({plane}, options);
  const Camera cam = TestCamera();
  const Rigid3d pose =
      LookAt(Vector3d(0.05, -0.25, 0.45), Vector3d(0, 0, 0), Vector3d::UnitZ());
  cv::Mat grey, depth;
  const RenderStats stats = renderer.Render(cam, pose, &grey, &depth);
  ASSERT_EQ(grey.type(), CV_8UC1);
  ASSERT_EQ(depth.type(), CV_32FC1);
  EXPECT_EQ(stats.planes_drawn, 1);

  double sum_abs = 0, max_rel_depth = 0;
  int compared = 0, background_checked = 0, background_wrong = 0;
  const double margin = 2.0 / ppm;
  for (int v = 0; v < cam.height; ++v) {
    for (int u = 0; u < cam.width; ++u) {
      Vector3d x = Vector3d::Constant(1e9);
      double z = 0;
      const bool hit = CastToHorizontalPlane(cam, pose, u, v, 0.0, &x, &z);
      const double s = x.x() + 0.4, t = x.y() + 0.3;
      if (hit && s > margin && s < 0.8 - margin && t > margin &&
          t < 0.6 - margin) {
        sum_abs += std::abs(grey.at<uint8_t>(v, u) - Smooth(s, t));
        max_rel_depth = std::max(
            max_rel_depth, std::abs(depth.at<float>(v, u) - z) / z);
        ++compared;
      } else if (!hit || s < -margin || s > 0.8 + margin || t < -margin ||
                 t > 0.6 + margin) {
        ++background_checked;
        background_wrong += grey.at<uint8_t>(v, u) != 7 ||
                            depth.at<float>(v, u) != 0.f;
      }
    }
  }
  std::printf("compared %d px: mean abs error %.3f grey, max rel depth %.2e\n",
              compared, sum_abs / compared, max_rel_depth);
  ASSERT_GT(compared, 50000);
  ASSERT_GT(background_checked, 10000);
  EXPECT_LT(sum_abs / compared, 1.0);
  EXPECT_LT(max_rel_depth, 1e-4);
  EXPECT_EQ(background_wrong, 0);
  EXPECT_NEAR(stats.pixels_foreground, compared, 0.03 * compared);
}

TEST(RendererTest, FrontPlaneOccludesBackPlane) {
  const double ppm = 200;
  const TexturedPlane back =
      MakePlane(Vector3d(-0.5, -0.5, 0), Vector3d::UnitX(), Vector3d::UnitY(),
                ppm, 200, 200, [](double, double) { return 60.0; });
  const TexturedPlane front =
      MakePlane(Vector3d(-0.1, -0.1, 0.1), Vector3d::UnitX(),
                Vector3d::UnitY(), ppm, 40, 40,
                [](double, double) { return 200.0; });
  const Camera cam = TestCamera().Scaled(160, 120);
  const Rigid3d pose = LookAt(Vector3d(0.05, 0.03, 0.6), Vector3d(0, 0, 0),
                              Vector3d::UnitY());
  // The result must not depend on the drawing order.
  for (const bool front_first : {false, true}) {
    const Renderer renderer(front_first ? std::vector{front, back}
                                        : std::vector{back, front});
    cv::Mat grey, depth;
    const RenderStats stats = renderer.Render(cam, pose, &grey, &depth);
    EXPECT_EQ(stats.planes_drawn, 2);
    int front_pixels = 0, back_pixels = 0, wrong = 0;
    double max_rel_depth = 0;
    for (int v = 0; v < cam.height; ++v) {
      for (int u = 0; u < cam.width; ++u) {
        Vector3d xf = Vector3d::Constant(1e9), xb = xf;
        double zf = 0, zb = 0;
        CastToHorizontalPlane(cam, pose, u, v, 0.1, &xf, &zf);
        CastToHorizontalPlane(cam, pose, u, v, 0.0, &xb, &zb);
        const double m = 0.01;  // stay away from the front plane's border
        if (std::abs(xf.x()) < 0.1 - m && std::abs(xf.y()) < 0.1 - m) {
          ++front_pixels;
          wrong += std::abs(grey.at<uint8_t>(v, u) - 200) > 1;
          max_rel_depth = std::max(
              max_rel_depth, std::abs(depth.at<float>(v, u) - zf) / zf);
        } else if ((std::abs(xf.x()) > 0.1 + m || std::abs(xf.y()) > 0.1 + m) &&
                   std::abs(xb.x()) < 0.5 - m && std::abs(xb.y()) < 0.5 - m) {
          ++back_pixels;
          wrong += std::abs(grey.at<uint8_t>(v, u) - 60) > 1;
          max_rel_depth = std::max(
              max_rel_depth, std::abs(depth.at<float>(v, u) - zb) / zb);
        }
      }
    }
    EXPECT_GT(front_pixels, 1000);
    EXPECT_GT(back_pixels, 5000);
    EXPECT_EQ(wrong, 0);
    EXPECT_LT(max_rel_depth, 1e-4);
  }
}

TEST(RendererTest, PolygonAndUnseenTexelsShowBackground) {
  const double ppm = 200;
  // Left half unseen (alpha 0) with a bright colour that must not bleed.
  TexturedPlane plane =
      MakePlane(Vector3d(-0.5, -0.5, 0), Vector3d::UnitX(), Vector3d::UnitY(),
                ppm, 200, 200, [](double, double) { return 50.0; });
  for (int r = 0; r < 200; ++r) {
    for (int c = 0; c < 100; ++c) {
      plane.texture.at<cv::Vec4b>(r, c) = cv::Vec4b(255, 255, 255, 0);
    }
  }
  // Triangle polygon: (s, t) in metres.
  plane.polygon = {Vector2d(0.05, 0.05), Vector2d(0.95, 0.05),
                   Vector2d(0.95, 0.95)};
  RendererOptions options;
  options.background_grey = 0;
  const Renderer renderer({plane}, options);
  const Camera cam = TestCamera().Scaled(160, 120);
  const Rigid3d pose = LookAt(Vector3d(0.02, -0.03, 0.9), Vector3d(0, 0, 0),
                              Vector3d::UnitY());
  cv::Mat grey;
  renderer.Render(cam, pose, &grey);
  int inside = 0, outside = 0, wrong = 0;
  for (int v = 0; v < cam.height; ++v) {
    for (int u = 0; u < cam.width; ++u) {
      Vector3d x = Vector3d::Constant(1e9);
      double z = 0;
      CastToHorizontalPlane(cam, pose, u, v, 0.0, &x, &z);
      const double s = x.x() + 0.5, t = x.y() + 0.5, m = 0.02;
      const bool in = s > 0.5 + m && s < 0.95 - m && t > 0.05 + m &&
                      t < s - m;
      const bool out = s < 0.5 - m || s > 0.95 + m || t < 0.05 - m ||
                       t > s + m;
      if (in) {
        ++inside;
        wrong += std::abs(grey.at<uint8_t>(v, u) - 50) > 1;
      } else if (out) {
        ++outside;
        wrong += grey.at<uint8_t>(v, u) != 0;
      }
    }
  }
  EXPECT_GT(inside, 1000);
  EXPECT_GT(outside, 5000);
  EXPECT_EQ(wrong, 0);

  // From far away the coarse mip levels mix seen and unseen texels: thanks
  // to premultiplied alpha the result stays 50, never drifts to white.
  const Rigid3d far_pose = LookAt(Vector3d(0.1, 0.1, 12), Vector3d(0, 0, 0),
                                  Vector3d::UnitY());
  const RenderStats stats = renderer.Render(cam, far_pose, &grey);
  ASSERT_GT(stats.pixels_foreground, 5);
  for (int v = 0; v < cam.height; ++v) {
    for (int u = 0; u < cam.width; ++u) {
      const int g = grey.at<uint8_t>(v, u);
      EXPECT_TRUE(g == 0 || std::abs(g - 50) <= 1) << g;
    }
  }
}

// A grown plane keeps the extent its landmarks support: rendered whole by
// default, clipped to that extent for localization.
TEST(RendererTest, LandmarkPolygonClipsOnlyWhenAsked) {
  TexturedPlane plane =
      MakePlane(Vector3d(-0.5, -0.5, 0), Vector3d::UnitX(), Vector3d::UnitY(),
                200, 200, 200, [](double, double) { return 80.0; });
  plane.polygon = {Vector2d(0, 0), Vector2d(1, 0), Vector2d(1, 1),
                   Vector2d(0, 1)};
  // The left half (s < 0.5): what the landmarks support.
  plane.landmark_polygon = {Vector2d(0, 0), Vector2d(0.5, 0),
                            Vector2d(0.5, 1), Vector2d(0, 1)};
  const Camera cam = TestCamera().Scaled(160, 120);
  const Rigid3d pose = LookAt(Vector3d(0.01, -0.02, 0.8), Vector3d(0, 0, 0),
                              Vector3d::UnitY());
  int drawn[2][2] = {{0, 0}, {0, 0}};  // [clip][s >= 0.5]
  for (int clip = 0; clip < 2; ++clip) {
    RendererOptions options;
    options.clip_to_landmark_polygon = clip == 1;
    const Renderer renderer({plane}, options);
    cv::Mat grey, depth;
    renderer.Render(cam, pose, &grey, &depth);
    for (int v = 0; v < cam.height; ++v) {
      for (int u = 0; u < cam.width; ++u) {
        Vector3d x;
        double z = 0;
        if (!CastToHorizontalPlane(cam, pose, u, v, 0.0, &x, &z)) continue;
        const double s = x.x() + 0.5, t = x.y() + 0.5;
        if (t < 0.02 || t > 0.98 || s < 0.02 || s > 0.98 ||
            std::abs(s - 0.5) < 0.02) {
          continue;  // near an edge
        }
        drawn[clip][s >= 0.5] += depth.at<float>(v, u) > 0 ? 1 : 0;
      }
    }
  }
  EXPECT_GT(drawn[0][0], 1000);
  EXPECT_GT(drawn[0][1], 1000);
  EXPECT_EQ(drawn[1][0], drawn[0][0]);  // the supported half: all of it
  EXPECT_EQ(drawn[1][1], 0);            // the grown half: none of it
}

// Variance of the foreground pixels.
double ForegroundVariance(const cv::Mat& grey, const cv::Mat& depth,
                          int* count) {
  double sum = 0, sum2 = 0;
  *count = 0;
  for (int v = 0; v < grey.rows; ++v) {
    for (int u = 0; u < grey.cols; ++u) {
      if (depth.at<float>(v, u) <= 0) continue;
      const double g = grey.at<uint8_t>(v, u);
      sum += g;
      sum2 += g * g;
      ++*count;
    }
  }
  const double mean = sum / *count;
  return sum2 / *count - mean * mean;
}

TEST(RendererTest, MipmapsRemoveAliasingOfMinifiedCheckerboard) {
  const double ppm = 1000;  // 2-texel squares: 2 mm
  const TexturedPlane plane = MakePlane(
      Vector3d(0, 0, 0), Vector3d::UnitX(), Vector3d::UnitY(), ppm, 512, 512,
      [](double s, double t) {
        const int a = static_cast<int>(std::floor(s * 500));
        const int b = static_cast<int>(std::floor(t * 500));
        return ((a + b) % 2) ? 255.0 : 0.0;
      });
  const Camera cam = TestCamera().Scaled(160, 120);
  const Rigid3d pose = LookAt(Vector3d(0.55, 0.2, 1.5),
                              Vector3d(0.256, 0.256, 0), Vector3d::UnitY());
  RendererOptions with_mip;
  RendererOptions without_mip;
  without_mip.use_mipmaps = false;
  cv::Mat grey, depth;
  int n_mip = 0, n_plain = 0;
  Renderer(std::vector{plane}, with_mip).Render(cam, pose, &grey, &depth);
  const double var_mip = ForegroundVariance(grey, depth, &n_mip);
  Renderer(std::vector{plane}, without_mip).Render(cam, pose, &grey, &depth);
  const double var_plain = ForegroundVariance(grey, depth, &n_plain);
  std::printf("variance with mipmaps %.1f, without %.1f (%d px)\n", var_mip,
              var_plain, n_mip);
  ASSERT_GT(n_mip, 1000);
  EXPECT_NEAR(n_mip, n_plain, 0.02 * n_mip);
  EXPECT_LT(var_mip, 30.0);       // std < 5.5 grey levels
  EXPECT_GT(var_plain, 2000.0);   // aliasing: std > 45 grey levels
  EXPECT_GT(var_plain / (var_mip + 1.0), 50.0);
}

// NCC of two grey images over the pixels where `mask` is set.
double MaskedNcc(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask) {
  cv::Scalar ma, sa, mb, sb;
  cv::meanStdDev(a, ma, sa, mask);
  cv::meanStdDev(b, mb, sb, mask);
  double sum = 0;
  int n = 0;
  for (int v = 0; v < a.rows; ++v) {
    for (int u = 0; u < a.cols; ++u) {
      if (!mask.at<uint8_t>(v, u)) continue;
      sum += (a.at<uint8_t>(v, u) - ma[0]) * (b.at<uint8_t>(v, u) - mb[0]);
      ++n;
    }
  }
  return sum / (n * sa[0] * sb[0]);
}

// A floor seen at a grazing angle: the area footprint keeps what a camera
// sees (the reference: a 4x finer render box-downscaled, as a live image
// is), the longest-axis footprint blurs the boards across the view away.
TEST(RendererTest, AreaFootprintMatchesBoxDownscaledObliqueView) {
  const TexturedPlane floor =
      MakePlane(Vector3d(-1, 0, 0), Vector3d::UnitX(), Vector3d::UnitY(), 400,
                800, 1600, [](double s, double t) {
                  // Boards 10 cm wide with dark 5 mm joints, a grain along
                  // them.
                  const double joint = std::fmod(s, 0.1) < 0.005 ? -90.0 : 0.0;
                  return 140.0 + joint + 30.0 * std::sin(2 * M_PI * t / 0.03);
                });
  const Camera small = TestCamera().Scaled(160, 120);
  const Camera large = TestCamera().Scaled(640, 480);
  const Rigid3d pose =
      LookAt(Vector3d(0, 0.2, 0.4), Vector3d(0, 2.5, 0), Vector3d::UnitZ());
  cv::Mat fine, reference, depth;
  RendererOptions sharp;
  sharp.mip_bias = 0.0;
  Renderer(std::vector{floor}, sharp).Render(large, pose, &fine);
  cv::resize(fine, reference, cv::Size(160, 120), 0, 0, cv::INTER_AREA);
  // Without bias: the footprints alone; then the defaults.
  std::vector<double> ncc;
  for (int k = 0; k < 3; ++k) {
    RendererOptions options;
    if (k < 2) options.mip_bias = 0.0;
    if (k == 1) options.mip_footprint = MipFootprint::kLongestAxis;
    cv::Mat grey;
    Renderer(std::vector{floor}, options).Render(small, pose, &grey, &depth);
    // Away from the floor's far edge, where box downscaling mixes in
    // background.
    cv::Mat mask = depth > 0.0f;
    cv::erode(mask, mask, cv::Mat(), cv::Point(-1, -1), 2);
    ASSERT_GT(cv::countNonZero(mask), 8000);
    ncc.push_back(MaskedNcc(grey, reference, mask));
  }
  std::printf(
      "NCC with the box-downscaled view: area %.3f, longest axis %.3f, "
      "defaults %.3f\n",
      ncc[0], ncc[1], ncc[2]);
  // Measured: 0.849, 0.686 and 0.849.
  EXPECT_GT(ncc[0], 0.8);
  EXPECT_GT(ncc[0] - ncc[1], 0.1);
  EXPECT_GT(ncc[2] - ncc[1], 0.1);
}

// Large renders split their rows over threads; the split must not change a
// pixel, also where one plane occludes another.
TEST(RendererTest, ParallelRowsRenderLikeOneThread) {
  const TexturedPlane back =
      MakePlane(Vector3d(-1, -1, 0), Vector3d::UnitX(), Vector3d::UnitY(), 300,
                600, 600, Smooth);
  const TexturedPlane front =
      MakePlane(Vector3d(-0.3, -0.3, 0.2), Vector3d::UnitX(),
                Vector3d(0, 1, 0.5), 300, 180, 200, [](double s, double t) {
                  return 60.0 + 120.0 * (std::fmod(s + t, 0.05) < 0.025);
                });
  const Renderer renderer({back, front});
  const Camera cam = TestCamera();  // 640x480: above the parallel threshold
  const Rigid3d pose =
      LookAt(Vector3d(0.2, -0.1, 1.5), Vector3d(0, 0, 0), -Vector3d::UnitY());
  cv::Mat serial, serial_depth, parallel, parallel_depth;
  RenderStats serial_stats;
  {
    const tbb::global_control one(tbb::global_control::max_allowed_parallelism,
                                  1);
    serial_stats = renderer.Render(cam, pose, &serial, &serial_depth);
  }
  const RenderStats stats =
      renderer.Render(cam, pose, &parallel, &parallel_depth);
  EXPECT_EQ(stats.planes_drawn, 2);
  EXPECT_EQ(stats.planes_drawn, serial_stats.planes_drawn);
  EXPECT_EQ(stats.pixels_foreground, serial_stats.pixels_foreground);
  EXPECT_GT(stats.pixels_foreground, cam.width * cam.height / 2);
  EXPECT_EQ(cv::norm(serial, parallel, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(serial_depth, parallel_depth, cv::NORM_INF), 0.0);
  // Both depths appear: the front plane occludes part of the back one.
  double z_min = 0, z_max = 0;
  cv::minMaxLoc(parallel_depth, &z_min, &z_max, nullptr, nullptr,
                parallel_depth > 0.0f);
  EXPECT_LT(z_min, 1.45);
  EXPECT_GT(z_max, 1.45);
}

TEST(RendererTest, PlaneBehindOrOutsideRendersBackground) {
  const TexturedPlane plane =
      MakePlane(Vector3d(-0.5, -0.5, 0), Vector3d::UnitX(), Vector3d::UnitY(),
                200, 200, 200, Smooth);
  RendererOptions options;
  options.background_grey = 33;
  const Renderer renderer({plane}, options);
  const Camera cam = TestCamera().Scaled(80, 60);
  cv::Mat grey, depth;
  const cv::Mat background(60, 80, CV_8UC1, cv::Scalar(33));

  // Seen from below, i.e. from behind its normal: culled.
  RenderStats stats = renderer.Render(
      cam, LookAt(Vector3d(0, 0, -0.5), Vector3d(0, 0, 0), Vector3d::UnitY()),
      &grey, &depth);
  EXPECT_EQ(stats.planes_drawn, 0);
  EXPECT_EQ(stats.pixels_foreground, 0);
  EXPECT_EQ(cv::norm(grey, background, cv::NORM_INF), 0);
  EXPECT_EQ(cv::countNonZero(depth), 0);
  // Without culling the back face is drawn.
  RendererOptions no_cull = options;
  no_cull.cull_back_faces = false;
  stats = Renderer({plane}, no_cull)
              .Render(cam,
                      LookAt(Vector3d(0, 0, -0.5), Vector3d(0, 0, 0),
                             Vector3d::UnitY()),
                      &grey);
  EXPECT_EQ(stats.pixels_foreground, 80 * 60);

  // Looking away from the plane (it is behind the camera).
  stats = renderer.Render(
      cam, LookAt(Vector3d(0, 0, 0.5), Vector3d(0, 0, 1), Vector3d::UnitY()),
      &grey, &depth);
  EXPECT_EQ(stats.pixels_foreground, 0);
  EXPECT_EQ(cv::norm(grey, background, cv::NORM_INF), 0);

  // Beside the plane, looking sideways: outside the view.
  stats = renderer.Render(
      cam, LookAt(Vector3d(3, 0, 0.5), Vector3d(6, 0, 0.5), Vector3d::UnitZ()),
      &grey, &depth);
  EXPECT_EQ(stats.pixels_foreground, 0);

  // Camera 5 mm above the plane looking along it: the plane crosses the
  // near plane; the lower half of the image shows it, never closer than
  // z_near.
  stats = renderer.Render(cam,
                          LookAt(Vector3d(-0.45, 0, 0.005),
                                 Vector3d(1, 0, 0.005), Vector3d::UnitZ()),
                          &grey, &depth);
  EXPECT_GT(stats.pixels_foreground, 0);
  EXPECT_LT(stats.pixels_foreground, 80 * 30 + 80);
  double min_depth = 1e9;
  for (int v = 0; v < 60; ++v) {
    for (int u = 0; u < 80; ++u) {
      const float d = depth.at<float>(v, u);
      if (d > 0) min_depth = std::min<double>(min_depth, d);
    }
  }
  EXPECT_GE(min_depth, options.z_near_m * 0.999);
}

TEST(RendererTest, ScaledCameraRendersAreConsistent) {
  // Wavelengths of ~25 pixels of the small render: the filters differ (8x8
  // box vs mip level) but agree closely.
  const TexturedPlane plane =
      MakePlane(Vector3d(-0.4, -0.3, 0), Vector3d::UnitX(), Vector3d::UnitY(),
                500, 400, 300, [](double s, double t) {
                  return 128 + 90 * std::sin(2 * M_PI * s / 0.3) *
                                   std::cos(2 * M_PI * t / 0.25);
                });
  const Renderer renderer({plane});
  const Camera cam = TestCamera();
  const Rigid3d pose =
      LookAt(Vector3d(0.1, -0.35, 0.5), Vector3d(0, 0, 0), Vector3d::UnitZ());
  cv::Mat big, big_depth, small, small_depth, reduced;
  renderer.Render(cam, pose, &big, &big_depth);
  renderer.Render(cam.Scaled(80, 60), pose, &small, &small_depth);
  cv::resize(big, reduced, cv::Size(80, 60), 0, 0, cv::INTER_AREA);
  double sum = 0;
  int n = 0;
  for (int v = 0; v < 60; ++v) {
    for (int u = 0; u < 80; ++u) {
      // Only blocks fully covered by the plane in the big render.
      const cv::Mat block = big_depth(cv::Rect(8 * u, 8 * v, 8, 8));
      if (cv::countNonZero(block) < 64 || small_depth.at<float>(v, u) <= 0) {
        continue;
      }
      sum += std::abs(small.at<uint8_t>(v, u) - reduced.at<uint8_t>(v, u));
      ++n;
    }
  }
  std::printf("80x60 vs reduced 640x480: mean abs diff %.3f over %d px\n",
              sum / n, n);
  ASSERT_GT(n, 2000);
  EXPECT_LT(sum / n, 2.0);
}

TEST(RendererTest, ColorRenderMatchesTexture) {
  TexturedPlane plane =
      MakePlane(Vector3d(-0.5, -0.5, 0), Vector3d::UnitX(), Vector3d::UnitY(),
                200, 200, 200, [](double, double) { return 0.0; });
  plane.texture.setTo(cv::Scalar(30, 120, 220, 255));
  RendererOptions options;
  options.enable_color = true;
  const Renderer renderer({plane}, options);
  const Camera cam = TestCamera().Scaled(80, 60);
  const Rigid3d pose =
      LookAt(Vector3d(0, 0, 0.5), Vector3d(0, 0, 0), Vector3d::UnitY());
  cv::Mat bgr, grey;
  const RenderStats stats = renderer.RenderColor(cam, pose, &bgr);
  ASSERT_EQ(bgr.type(), CV_8UC3);
  EXPECT_EQ(stats.pixels_foreground, 80 * 60);
  EXPECT_LE(cv::norm(bgr, cv::Mat(60, 80, CV_8UC3, cv::Scalar(30, 120, 220)),
                     cv::NORM_INF),
            1);
  renderer.Render(cam, pose, &grey);
  // 0.114 B + 0.587 G + 0.299 R = 139.6
  EXPECT_LE(cv::norm(grey, cv::Mat(60, 80, CV_8UC1, cv::Scalar(140)),
                     cv::NORM_INF),
            1);
  // Colour needs enable_color.
  EXPECT_THROW(Renderer({plane}).RenderColor(cam, pose, &bgr), OptionsError);
}

TEST(RendererTest, BatchMatchesSingleRenders) {
  const TexturedPlane plane =
      MakePlane(Vector3d(-0.4, -0.3, 0), Vector3d::UnitX(), Vector3d::UnitY(),
                500, 400, 300, Smooth);
  const Renderer renderer({plane});
  const Camera cam = TestCamera().Scaled(80, 60);
  std::vector<Rigid3d> poses;
  for (int i = 0; i < 50; ++i) {
    poses.push_back(LookAt(Vector3d(0.01 * i - 0.25, -0.2, 0.4 + 0.004 * i),
                           Vector3d(0, 0, 0), Vector3d::UnitZ()));
  }
  std::vector<cv::Mat> greys, depths;
  const std::vector<RenderStats> stats =
      renderer.RenderBatch(cam, poses, &greys, &depths);
  ASSERT_EQ(stats.size(), poses.size());
  ASSERT_EQ(greys.size(), poses.size());
  ASSERT_EQ(depths.size(), poses.size());
  for (size_t i = 0; i < poses.size(); ++i) {
    cv::Mat grey, depth;
    const RenderStats single = renderer.Render(cam, poses[i], &grey, &depth);
    EXPECT_EQ(stats[i].pixels_foreground, single.pixels_foreground);
    EXPECT_GT(single.pixels_foreground, 1000);
    EXPECT_EQ(cv::norm(grey, greys[i], cv::NORM_INF), 0);
    EXPECT_EQ(cv::norm(depth, depths[i], cv::NORM_INF), 0);
  }
}

TEST(RendererTest, OptionsAndInputsAreChecked) {
  RendererOptions options;
  options.alpha_threshold = 0;
  EXPECT_THROW(options.Check(), OptionsError);
  options = RendererOptions();
  options.background_grey = 300;
  EXPECT_THROW(Renderer(std::vector<TexturedPlane>{}, options), OptionsError);
  TexturedPlane plane;
  plane.pixels_per_meter = 100;
  plane.texture = cv::Mat(4, 4, CV_32FC1, cv::Scalar(0));
  EXPECT_THROW(Renderer(std::vector{plane}), InputError);
  plane.texture = cv::Mat(4, 4, CV_8UC4, cv::Scalar(0));
  plane.pixels_per_meter = 0;
  EXPECT_THROW(Renderer(std::vector{plane}), InputError);
}

}  // namespace
}  // namespace monomap
