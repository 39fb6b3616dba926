#include "monomap/sim/image_synthesis.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "monomap/sim/world.h"
#include "monomap/util/error.h"

namespace monomap {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

// Bilinear BGR sample of an 8-bit image at (x, y), clamped to the border.
inline Eigen::Vector3f SampleBilinear(const cv::Mat& img, double x, double y) {
  x = std::clamp(x, 0.0, img.cols - 1.0);
  y = std::clamp(y, 0.0, img.rows - 1.0);
  const int x0 = std::min(static_cast<int>(x), img.cols - 2 < 0 ? 0 : img.cols - 2);
  const int y0 = std::min(static_cast<int>(y), img.rows - 2 < 0 ? 0 : img.rows - 2);
  const int x1 = std::min(x0 + 1, img.cols - 1);
  const int y1 = std::min(y0 + 1, img.rows - 1);
  const float fx = static_cast<float>(x - x0), fy = static_cast<float>(y - y0);
  const cv::Vec3b& a = img.at<cv::Vec3b>(y0, x0);
  const cv::Vec3b& b = img.at<cv::Vec3b>(y0, x1);
  const cv::Vec3b& c = img.at<cv::Vec3b>(y1, x0);
  const cv::Vec3b& d = img.at<cv::Vec3b>(y1, x1);
  Eigen::Vector3f out;
  for (int k = 0; k < 3; ++k) {
    const float top = a[k] + fx * (b[k] - a[k]);
    const float bot = c[k] + fx * (d[k] - c[k]);
    out[k] = top + fy * (bot - top);
  }
  return out;
}

// Trilinear sample at level-0 texel coordinates (u, v) and mip level.
Eigen::Vector3f SampleMip(const std::vector<cv::Mat>& levels, double u,
                          double v, double level) {
  const int max_level = static_cast<int>(levels.size()) - 1;
  level = std::clamp(level, 0.0, static_cast<double>(max_level));
  const int l0 = static_cast<int>(level);
  const int l1 = std::min(l0 + 1, max_level);
  const double f = level - l0;
  // cv::pyrDown centres texel i of level l on texel i * 2^l of level 0.
  auto at = [&](int l) {
    const double s = 1.0 / static_cast<double>(1 << l);
    return SampleBilinear(levels[l], u * s, v * s);
  };
  const Eigen::Vector3f a = at(l0);
  if (f <= 1e-6 || l1 == l0) return a;
  return a + static_cast<float>(f) * (at(l1) - a);
}

}  // namespace

void RenderOptions::Check() const {
  CheckOption(supersampling >= 1 && supersampling <= 4,
              "render.supersampling", "must be in [1, 4]");
  CheckOption(background >= 0 && background <= 255, "render.background",
              "must be in [0, 255]");
}

SceneRenderer::SceneRenderer(const Camera& camera,
                             const RenderOptions& options)
    : camera_(camera), options_(options) {
  camera_.Check();
  options_.Check();
  const int ss = options_.supersampling;
  grid_w_ = camera_.width * ss;
  grid_h_ = camera_.height * ss;
  rays_.resize(static_cast<size_t>(grid_w_) * grid_h_);
  tbb::parallel_for(tbb::blocked_range<int>(0, grid_h_),
                    [&](const tbb::blocked_range<int>& r) {
    for (int gy = r.begin(); gy < r.end(); ++gy) {
      for (int gx = 0; gx < grid_w_; ++gx) {
        const Vector2d px((gx + 0.5) / ss - 0.5, (gy + 0.5) / ss - 0.5);
        rays_[static_cast<size_t>(gy) * grid_w_ + gx] =
            camera_.NormalizedFromImage(px).homogeneous();
      }
    }
  });
  // Angular size of a sample from the spacing of neighbouring rays.
  ray_angle_.resize(rays_.size());
  auto unit = [&](int gx, int gy) {
    return rays_[static_cast<size_t>(gy) * grid_w_ + gx].normalized();
  };
  for (int gy = 0; gy < grid_h_; ++gy) {
    for (int gx = 0; gx < grid_w_; ++gx) {
      const int xa = std::max(gx - 1, 0), xb = std::min(gx + 1, grid_w_ - 1);
      const int ya = std::max(gy - 1, 0), yb = std::min(gy + 1, grid_h_ - 1);
      const double ax = (unit(xb, gy) - unit(xa, gy)).norm() /
                        std::max(1, xb - xa);
      const double ay = (unit(gx, yb) - unit(gx, ya)).norm() /
                        std::max(1, yb - ya);
      ray_angle_[static_cast<size_t>(gy) * grid_w_ + gx] =
          static_cast<float>(0.5 * (ax + ay));
    }
  }
}

int SceneRenderer::AddPlane(const TexturedPlane& plane) {
  CheckOption(!plane.texture.empty(), "render.plane",
              "plane " + std::to_string(plane.id) + " has no texture");
  CheckOption(plane.pixels_per_meter > 0, "render.plane",
              "plane " + std::to_string(plane.id) +
                  " has pixels_per_meter <= 0");
  CheckOption(plane.polygon.size() >= 3, "render.plane",
              "plane " + std::to_string(plane.id) +
                  " has fewer than 3 polygon vertices");
  Entry e;
  e.plane = plane.plane;
  e.frame = plane.frame;
  e.polygon = plane.polygon;
  PolygonBounds(e.polygon, &e.lo, &e.hi);
  e.ppm = plane.pixels_per_meter;
  cv::Mat bgr;
  switch (plane.texture.channels()) {
    case 4: cv::cvtColor(plane.texture, bgr, cv::COLOR_BGRA2BGR); break;
    case 1: cv::cvtColor(plane.texture, bgr, cv::COLOR_GRAY2BGR); break;
    default: bgr = plane.texture.clone();
  }
  if (bgr.depth() != CV_8U) bgr.convertTo(bgr, CV_8U);
  e.levels.push_back(bgr);
  while (e.levels.back().cols > 2 && e.levels.back().rows > 2) {
    cv::Mat next;
    cv::pyrDown(e.levels.back(), next);
    e.levels.push_back(next);
  }
  planes_.push_back(std::move(e));
  return static_cast<int>(planes_.size()) - 1;
}

void SceneRenderer::SetPlanePose(int i, const Plane& plane,
                                 const PlaneFrame& frame) {
  planes_.at(i).plane = plane;
  planes_.at(i).frame = frame;
}

void SceneRenderer::SetPlaneVisible(int i, bool visible) {
  planes_.at(i).visible = visible;
}

int SceneRenderer::Intersect(const Vector3d& c, const Vector3d& d,
                             const std::vector<double>& c_dist,
                             double* t_hit, Vector2d* st_hit) const {
  int best = -1;
  double best_t = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < planes_.size(); ++i) {
    const Entry& e = planes_[i];
    if (!e.visible) continue;
    const double denom = e.plane.normal.dot(d);
    if (std::abs(denom) < 1e-12) continue;
    const double t = -c_dist[i] / denom;
    if (t <= 1e-6 || t >= best_t) continue;
    const Vector3d x = c + t * d;
    const Vector2d st = e.frame.ToPlane(x);
    if (st.x() < e.lo.x() || st.y() < e.lo.y() || st.x() > e.hi.x() ||
        st.y() > e.hi.y()) {
      continue;
    }
    if (!PointInPolygon(e.polygon, st)) continue;
    best = static_cast<int>(i);
    best_t = t;
    *st_hit = st;
  }
  *t_hit = best_t;
  return best;
}

cv::Mat SceneRenderer::Render(const Rigid3d& world_from_cam,
                              const std::vector<Highlight>& highlights) const {
  const Eigen::Matrix3d r = world_from_cam.RotationMatrix();
  const Vector3d c = world_from_cam.translation;
  std::vector<double> c_dist(planes_.size());
  for (size_t i = 0; i < planes_.size(); ++i) {
    c_dist[i] = planes_[i].plane.SignedDistance(c);
  }
  const int ss = options_.supersampling;
  const float inv_n = 1.0f / static_cast<float>(ss * ss);
  const float bg = static_cast<float>(options_.background);
  cv::Mat out(camera_.height, camera_.width, CV_32FC3);
  tbb::parallel_for(tbb::blocked_range<int>(0, camera_.height),
                    [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y < rows.end(); ++y) {
      for (int x = 0; x < camera_.width; ++x) {
        Eigen::Vector3f acc = Eigen::Vector3f::Zero();
        for (int sy = 0; sy < ss; ++sy) {
          for (int sx = 0; sx < ss; ++sx) {
            const size_t g = static_cast<size_t>(y * ss + sy) * grid_w_ +
                             (x * ss + sx);
            const Vector3d d = r * rays_[g];
            double t = 0;
            Vector2d st;
            const int hit = Intersect(c, d, c_dist, &t, &st);
            if (hit < 0) {
              acc += Eigen::Vector3f::Constant(bg);
              continue;
            }
            const Entry& e = planes_[hit];
            const double dn = d.norm();
            // Footprint of the sample on the plane in texels: across the
            // ray it is range * angle; along the slant it grows by 1/cos.
            const double cos_inc =
                std::max(std::abs(e.plane.normal.dot(d)) / dn, 0.05);
            const double minor = t * dn * ray_angle_[g] * e.ppm;
            const double level =
                std::log2(std::max(minor, 1e-9)) - 0.6 * std::log2(cos_inc);
            Eigen::Vector3f v = SampleMip(e.levels, st.x() * e.ppm - 0.5,
                                          st.y() * e.ppm - 0.5, level);
            for (const Highlight& h : highlights) {
              if (h.plane_index != hit) continue;
              const Vector3d xw = c + t * d;
              const double q = (xw - h.centre).squaredNorm() /
                               (2.0 * h.radius_m * h.radius_m);
              if (q < 20.0) {
                v += Eigen::Vector3f::Constant(
                    static_cast<float>(h.strength * std::exp(-q)));
              }
            }
            acc += v;
          }
        }
        acc *= inv_n;
        out.at<cv::Vec3f>(y, x) = cv::Vec3f(acc[0], acc[1], acc[2]);
      }
    }
  });
  return out;
}

cv::Mat SceneRenderer::RenderPlaneIndex(const Rigid3d& world_from_cam) const {
  const Eigen::Matrix3d r = world_from_cam.RotationMatrix();
  const Vector3d c = world_from_cam.translation;
  std::vector<double> c_dist(planes_.size());
  for (size_t i = 0; i < planes_.size(); ++i) {
    c_dist[i] = planes_[i].plane.SignedDistance(c);
  }
  cv::Mat out(camera_.height, camera_.width, CV_32S);
  for (int y = 0; y < camera_.height; ++y) {
    for (int x = 0; x < camera_.width; ++x) {
      const Vector3d d =
          r * camera_.NormalizedFromImage(Vector2d(x, y)).homogeneous();
      double t;
      Vector2d st;
      out.at<int>(y, x) = Intersect(c, d, c_dist, &t, &st);
    }
  }
  return out;
}

CameraEffectsOptions CameraEffectsOptions::None() {
  CameraEffectsOptions o;
  o.exposure_variation = 0.0;
  o.blur_sigma_px = 0.0;
  o.noise_sigma = 0.0;
  return o;
}

void CameraEffectsOptions::Check() const {
  CheckOption(exposure_variation >= 0 && exposure_variation < 0.8,
              "effects.exposure_variation", "must be in [0, 0.8)");
  CheckOption(exposure_period_s > 0, "effects.exposure_period_s",
              "must be > 0");
  CheckOption(blur_sigma_px >= 0 && blur_sigma_px <= 10,
              "effects.blur_sigma_px", "must be in [0, 10]");
  CheckOption(noise_sigma >= 0 && noise_sigma <= 50, "effects.noise_sigma",
              "must be in [0, 50]");
}

double ExposureGain(double t, const CameraEffectsOptions& options,
                    uint64_t seed) {
  if (options.exposure_variation <= 0) return 1.0;
  // Two incommensurate sines with seeded phases: smooth, never periodic
  // within a sequence, within +-variation of 1.
  const double phase1 = (SimMixSeed(seed, 101) % 6283) * 1e-3;
  const double phase2 = (SimMixSeed(seed, 102) % 6283) * 1e-3;
  const double w = 2.0 * M_PI / options.exposure_period_s;
  return 1.0 + options.exposure_variation *
                   (0.65 * std::sin(w * t + phase1) +
                    0.35 * std::sin(2.37 * w * t + phase2));
}

cv::Mat ApplyCameraEffects(const cv::Mat& radiance, double t,
                           const CameraEffectsOptions& options, uint64_t seed,
                           uint64_t noise_seed) {
  options.Check();
  cv::Mat img;
  if (!options.color && radiance.channels() == 3) {
    cv::cvtColor(radiance, img, cv::COLOR_BGR2GRAY);
  } else {
    img = radiance.clone();  // the input stays untouched
  }
  if (options.blur_sigma_px > 0) {
    cv::GaussianBlur(img, img, cv::Size(0, 0), options.blur_sigma_px, 0,
                     cv::BORDER_REFLECT);
  }
  const double gain = ExposureGain(t, options, seed);
  if (gain != 1.0) img = img * gain;
  if (options.noise_sigma > 0) {
    cv::Mat noise(img.size(), img.type());
    cv::RNG rng(noise_seed);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, options.noise_sigma);
    img = img + noise;
  }
  cv::Mat out;
  img.convertTo(out, options.color ? CV_8UC3 : CV_8UC1);
  return out;
}

TexturedPlane MakeDiscObject(double radius_m, double pixels_per_meter,
                             uint64_t seed) {
  CheckOption(radius_m > 0, "moving_object.radius_m", "must be > 0");
  TexturedPlane p = MakeRectanglePlane(-1, Vector3d::Zero(), Vector3d::UnitX(),
                                       -Vector3d::UnitZ(), 2 * radius_m,
                                       2 * radius_m, pixels_per_meter);
  cv::Mat img(p.texture.size(), CV_8UC3);
  // Checkerboard with coloured rings and random dots: unmistakable.
  const int cell = std::max(2, static_cast<int>(0.05 * pixels_per_meter));
  for (int y = 0; y < img.rows; ++y) {
    for (int x = 0; x < img.cols; ++x) {
      const bool on = ((x / cell) + (y / cell)) % 2 == 0;
      img.at<cv::Vec3b>(y, x) = on ? cv::Vec3b(30, 30, 200)
                                   : cv::Vec3b(240, 240, 60);
    }
  }
  const cv::Point centre(img.cols / 2, img.rows / 2);
  for (int k = 1; k <= 3; ++k) {
    cv::circle(img, centre, img.cols * k / 8, cv::Scalar(10, 10, 10),
               std::max(1, cell / 3), cv::LINE_AA);
  }
  cv::RNG rng(seed);
  for (int i = 0; i < 30; ++i) {
    cv::circle(img, {rng.uniform(0, img.cols), rng.uniform(0, img.rows)},
               std::max(1, cell / 3), cv::Scalar(255, 255, 255), -1);
  }
  cv::cvtColor(img, p.texture, cv::COLOR_BGR2BGRA);
  p.polygon.clear();
  constexpr int kVertices = 32;
  for (int i = 0; i < kVertices; ++i) {
    const double a = 2.0 * M_PI * i / kVertices;
    p.polygon.emplace_back(radius_m * (1.0 + std::cos(a)),
                           radius_m * (1.0 + std::sin(a)));
  }
  return p;
}

void PlaceDisc(double radius_m, const Vector3d& centre,
               const Vector3d& towards, Plane* plane, PlaneFrame* frame) {
  const Vector3d n = towards.normalized();
  // Upright: v points down as far as the normal allows.
  Vector3d v = -Vector3d::UnitZ() + n.z() * n;
  if (v.norm() < 1e-6) v = Vector3d::UnitY();
  v.normalize();
  const Vector3d u = v.cross(n);  // u x v = n
  frame->u_axis = u;
  frame->v_axis = v;
  frame->origin = centre - radius_m * u - radius_m * v;
  plane->normal = n;
  plane->offset = -n.dot(centre);
}

bool SpecularPoint(const Vector3d& light, const Vector3d& camera_centre,
                   double floor_z, Vector3d* point) {
  const double hl = light.z() - floor_z, hc = camera_centre.z() - floor_z;
  if (hl <= 0 || hc <= 0) return false;
  // The reflection point splits the horizontal offset in the ratio of the
  // heights (equal angles of incidence and reflection).
  const double f = hc / (hc + hl);
  *point = camera_centre + f * (light - camera_centre);
  point->z() = floor_z;
  return true;
}

}  // namespace monomap
