#include "monomap/texture/mosaic.h"

#include <cmath>
#include <functional>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "monomap/sim/test_scene.h"
#include "monomap/util/error.h"

namespace monomap {
namespace {

using testing::ScenePlane;

Camera TestCamera() {
  Camera c;
  c.width = 320;
  c.height = 240;
  c.fx = 280;
  c.fy = 280;
  c.cx = 159.5;
  c.cy = 119.5;
  c.distortion = {-0.25, 0.08, 0.001, -0.0008, 0.0};
  return c;
}

std::vector<Rigid3d> TestPoses(int n) {
  std::vector<Rigid3d> poses;
  for (int i = 0; i < n; ++i) {
    const double a = 6.283185307179586 * i / n;
    const Eigen::Vector3d eye(0.3 + 0.1 * std::cos(a),
                              0.2 + 0.07 * std::sin(a),
                              0.55 + 0.04 * std::sin(2 * a));
    const Eigen::Vector3d target(0.3 + 0.02 * std::sin(a), 0.2, 0.0);
    poses.push_back(testing::LookAt(eye, target, Eigen::Vector3d::UnitY()));
  }
  return poses;
}

double Gain(int frame) { return 0.8 + 0.4 * ((frame * 7) % 12) / 11.0; }

// A scene rendered on demand (images cached).
struct Scene {
  Camera camera = TestCamera();
  std::vector<Rigid3d> poses;
  std::vector<ScenePlane> planes;
  std::vector<PlaneSegment> segments;
  std::vector<Landmark> landmarks;
  std::vector<Track> tracks;
  std::vector<cv::Mat> images;

  void Render(int supersample = 2) {
    testing::RayCaster caster(camera, supersample);
    images.clear();
    for (size_t f = 0; f < poses.size(); ++f) {
      images.push_back(caster.Render(poses[f], planes, static_cast<int>(f),
                                     Gain(static_cast<int>(f)), 2.0));
    }
  }
};

// A 0.6 x 0.4 m textured floor with 60 features.
Scene MakeScene(int num_frames) {
  testing::TestSceneOptions o;
  o.layout = testing::TestLayout::kDesk;
  o.camera = TestCamera();
  o.world_from_cam = TestPoses(num_frames);
  // The frame origin away from the polygon's min corner, so that the
  // mosaic has to shift it.
  o.desk.origin_shift_m = {0.1, 0.05};
  o.desk.num_features = 60;
  o.desk.feature_seed = 11;
  o.desk.texture_seed = 5;
  o.desk.texture_blobs = 25;
  o.desk.texture_extent_m = {0.7, 0.45};
  testing::TestScene t = testing::MakeTestScene(o);
  Scene s;
  s.poses = std::move(t.world_from_cam);
  s.planes = std::move(t.planes);
  s.segments = std::move(t.segments);
  s.landmarks = std::move(t.landmarks);
  s.tracks = std::move(t.tracks);
  return s;
}

// Normalised cross-correlation of mosaic luminance against the true
// texture over the texels with alpha > 0 that `mask` accepts (st in the
// segment's frame of `truth_segment`).
double TextureNcc(const TexturedPlane& tp, const PlaneSegment& truth_segment,
                  const std::function<Eigen::Vector3f(const Eigen::Vector2d&)>&
                      truth,
                  const std::function<bool(const Eigen::Vector2d&)>& mask,
                  int* count = nullptr) {
  double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
  int n = 0;
  for (int r = 0; r < tp.texture.rows; ++r) {
    for (int c = 0; c < tp.texture.cols; ++c) {
      const cv::Vec4b p = tp.texture.at<cv::Vec4b>(r, c);
      if (p[3] == 0) continue;
      const Eigen::Vector2d st = truth_segment.frame.ToPlane(
          tp.WorldFromTexture(Eigen::Vector2d(c, r)));
      if (!mask(st)) continue;
      const Eigen::Vector3f t = truth(st);
      const double a = 0.114 * p[0] + 0.587 * p[1] + 0.299 * p[2];
      const double b = 0.114 * t[0] + 0.587 * t[1] + 0.299 * t[2];
      sa += a;
      sb += b;
      saa += a * a;
      sbb += b * b;
      sab += a * b;
      ++n;
    }
  }
  if (count) *count = n;
  if (n < 2) return 0.0;
  const double cov = sab / n - sa / n * sb / n;
  const double va = saa / n - sa / n * sa / n;
  const double vb = sbb / n - sb / n * sb / n;
  return cov / std::sqrt(va * vb);
}

MosaicReport Build(const Scene& s, const MosaicOptions& options,
                   std::vector<TexturedPlane>* planes, bool grey = false) {
  std::vector<ImagePlaneHomography> hs;
  ComputeImagePlaneHomographies(s.camera, s.poses, s.segments, s.landmarks,
                                s.tracks, HomographyOptions(), &hs);
  auto loader = [&](int f) {
    if (!grey) return s.images[f];
    cv::Mat g;
    cv::cvtColor(s.images[f], g, cv::COLOR_BGR2GRAY);
    return g;
  };
  return BuildTexturedPlanes(s.camera, s.poses, s.segments, s.landmarks,
                             s.tracks, hs, loader, options, planes);
}

const auto kAll = [](const Eigen::Vector2d&) { return true; };

TEST(MosaicTest, RecoversKnownTexture) {
  Scene s = MakeScene(12);
  s.Render();
  std::vector<TexturedPlane> planes;
  const MosaicReport report = Build(s, MosaicOptions(), &planes);
  ASSERT_EQ(planes.size(), 1u);
  ASSERT_EQ(report.planes.size(), 1u);
  const TexturedPlane& tp = planes[0];
  const PlaneMosaicStats& st = report.planes[0];
  EXPECT_EQ(tp.id, 0);
  EXPECT_EQ(tp.texture.type(), CV_8UC4);
  // Resolution chosen from the images: about f / distance.
  EXPECT_GT(tp.pixels_per_meter, 400.0);
  EXPECT_LT(tp.pixels_per_meter, 650.0);
  EXPECT_EQ(tp.texture.cols, st.width);
  EXPECT_NEAR(st.width, 0.6 * tp.pixels_per_meter, 1.0);
  EXPECT_NEAR(st.height, 0.4 * tp.pixels_per_meter, 1.0);
  // Frame origin moved to the polygon's min corner.
  EXPECT_LT((tp.frame.origin - Eigen::Vector3d::Zero()).norm(), 1e-12);
  EXPECT_LT((tp.polygon[2] - Eigen::Vector2d(0.6, 0.4)).norm(), 1e-12);
  EXPECT_EQ(st.frames.size(), 12u);
  EXPECT_GT(st.coverage, 0.97);
  const auto& truth = s.planes[0].color;
  const double ncc = TextureNcc(
      tp, s.segments[0],
      [&](const Eigen::Vector2d& x) { return truth(0, x); }, kAll);
  EXPECT_GT(ncc, 0.97);
  // Features: texture_px of exact data matches where they appear.
  EXPECT_EQ(tp.features.size(), 60u);
  EXPECT_EQ(st.num_features, 60);
  EXPECT_LT(st.feature_residual_max_px, 0.5);
  EXPECT_LT(st.feature_residual_median_px, 0.01);
  for (const auto& f : tp.features) {
    EXPECT_LT((tp.WorldFromTexture(f.texture_px) - f.x_in_world).norm(),
              1e-9);
  }

  // Grey input works too.
  std::vector<TexturedPlane> grey_planes;
  Build(s, MosaicOptions(), &grey_planes, true);
  ASSERT_EQ(grey_planes.size(), 1u);
  EXPECT_GT(TextureNcc(grey_planes[0], s.segments[0],
                       [&](const Eigen::Vector2d& x) { return truth(0, x); },
                       kAll),
            0.97);
}

TEST(MosaicTest, MovingObjectAndHighlightsVanish) {
  Scene s = MakeScene(12);
  const auto texture = s.planes[0].color;
  // A striped object in 4 of 12 frames, moving by 1 cm each time, and a
  // specular highlight sweeping over the plane in every frame. Coordinates
  // in the floor segment's frame (polygon is [0.1, 0.7] x [0.05, 0.45]).
  s.planes[0].color = [texture](int frame, const Eigen::Vector2d& st) {
    Eigen::Vector3f c = texture(frame, st);
    if (frame % 3 == 1) {
      const double shift = 0.01 * (frame / 3);
      // Moves along the stripes so that they stay in phase.
      const Eigen::Vector2d lo(0.33, 0.2 + shift);
      if (st.x() > lo.x() && st.y() > lo.y() && st.x() < lo.x() + 0.12 &&
          st.y() < lo.y() + 0.1) {
        const bool white = std::fmod(st.x() - lo.x(), 0.02) < 0.01;
        c = white ? Eigen::Vector3f(255, 255, 255) : Eigen::Vector3f(0, 0, 0);
      }
    }
    const Eigen::Vector2d spot(0.15 + 0.5 * frame / 11.0,
                               0.12 + 0.12 * (frame % 3));
    const double w = std::exp(-(st - spot).squaredNorm() / (2 * 0.03 * 0.03));
    c += Eigen::Vector3f::Constant(static_cast<float>(200.0 * w));
    return c;
  };
  s.Render();
  const auto truth = [&](const Eigen::Vector2d& x) { return texture(0, x); };
  // Texels under the object in all four frames where it appears.
  const auto object = [](const Eigen::Vector2d& st) {
    return st.x() > 0.36 && st.y() > 0.23 && st.x() < 0.45 && st.y() < 0.3;
  };
  std::vector<TexturedPlane> robust;
  Build(s, MosaicOptions(), &robust);
  ASSERT_EQ(robust.size(), 1u);
  int n = 0;
  const double ncc_object = TextureNcc(robust[0], s.segments[0], truth,
                                       object, &n);
  EXPECT_GT(n, 1000);
  EXPECT_GT(ncc_object, 0.9);
  EXPECT_GT(TextureNcc(robust[0], s.segments[0], truth, kAll), 0.95);

  // A plain mean keeps the object and the highlights.
  MosaicOptions mean_options;
  mean_options.blend = BlendMode::kMean;
  std::vector<TexturedPlane> mean;
  Build(s, mean_options, &mean);
  ASSERT_EQ(mean.size(), 1u);
  const double mean_object = TextureNcc(mean[0], s.segments[0], truth, object);

  EXPECT_LT(mean_object, 0.85);
  std::printf("NCC under the object: robust %.3f, mean %.3f\n", ncc_object,
              mean_object);

  // The median also removes it.
  MosaicOptions median_options;
  median_options.blend = BlendMode::kMedian;
  std::vector<TexturedPlane> median;
  Build(s, median_options, &median);
  EXPECT_GT(TextureNcc(median[0], s.segments[0], truth, object), 0.9);
}

TEST(MosaicTest, OccludingPlaneDoesNotBleed) {
  Scene s = MakeScene(12);
  // A small striped red board 12 cm above the floor.
  PlaneSegment board =
      testing::HorizontalRectangle(1, 0.22, 0.14, 0.12, 0.16, 0.12);
  s.segments.push_back(board);
  s.planes.push_back({board, [](int, const Eigen::Vector2d& st) {
                        const bool a = std::fmod(st.x(), 0.02) < 0.01;
                        return a ? Eigen::Vector3f(20, 20, 250)
                                 : Eigen::Vector3f(250, 250, 20);
                      }});
  s.Render();
  const auto floor_truth = [&](const Eigen::Vector2d& x) {
    return s.planes[0].color(0, x);
  };
  // Floor texels near the board's footprint: hidden in some views, seen in
  // others. Floor frame: world (x, y) = st - (0.1, 0.05).
  const auto near_board = [](const Eigen::Vector2d& st) {
    const double x = st.x() - 0.1, y = st.y() - 0.05;
    return x > 0.14 && x < 0.46 && y > 0.06 && y < 0.34;
  };
  for (BlendMode mode : {BlendMode::kRobust, BlendMode::kMean}) {
    MosaicOptions options;
    options.blend = mode;
    std::vector<TexturedPlane> planes;
    const MosaicReport report = Build(s, options, &planes);
    ASSERT_EQ(planes.size(), 2u);
    int n = 0;
    const double ncc =
        TextureNcc(planes[0], s.segments[0], floor_truth, near_board, &n);
    EXPECT_GT(n, 2000);
    EXPECT_GT(ncc, 0.9);
    // The board itself is recovered and complete.
    EXPECT_GT(TextureNcc(planes[1], s.segments[1],
                         [&](const Eigen::Vector2d& x) {
                           return s.planes[1].color(0, x);
                         },
                         kAll),
              0.9);
    EXPECT_GT(report.planes[1].coverage, 0.97);
    // Right under the board's centre nothing sees the floor.
    const Eigen::Vector2d under =
        planes[0].TextureFromWorld(Eigen::Vector3d(0.3, 0.2, 0.0));
    EXPECT_EQ(planes[0].texture.at<cv::Vec4b>(static_cast<int>(under.y()),
                                              static_cast<int>(under.x()))[3],
              0);
    if (mode == BlendMode::kMean) {
      // Without the occlusion test the board bleeds into the floor.
      options.occlusion_test = false;
      std::vector<TexturedPlane> bleeding;
      Build(s, options, &bleeding);
      const double ncc_bleed = TextureNcc(bleeding[0], s.segments[0],
                                          floor_truth, near_board);
      std::printf("NCC near the board: occlusion test %.3f, without %.3f\n",
                  ncc, ncc_bleed);
      EXPECT_LT(ncc_bleed, ncc - 0.1);
    }
  }
}

TEST(MosaicTest, FrameSelectionAndSizeLimits) {
  Scene s = MakeScene(30);
  s.Render(1);
  MosaicOptions options;
  options.max_frames_per_plane = 7;
  options.max_texture_side = 150;
  std::vector<TexturedPlane> planes;
  const MosaicReport report = Build(s, options, &planes);
  ASSERT_EQ(report.planes.size(), 1u);
  const auto& st = report.planes[0];
  ASSERT_EQ(st.frames.size(), 7u);
  // Spread over the sequence: one per group of ~4 frames.
  for (size_t i = 0; i < st.frames.size(); ++i) {
    EXPECT_GE(st.frames[i], static_cast<int>(i * 30 / 7));
    EXPECT_LT(st.frames[i], static_cast<int>((i + 1) * 30 / 7));
  }
  EXPECT_LE(st.width, 150);
  EXPECT_LE(st.height, 150);
  EXPECT_NEAR(st.pixels_per_meter, 150 / 0.6, 1e-6);
  EXPECT_LT(st.feature_residual_max_px, 0.5);
}

TEST(MosaicTest, RejectsBadInput) {
  Scene s = MakeScene(3);
  std::vector<ImagePlaneHomography> hs;
  ComputeImagePlaneHomographies(s.camera, s.poses, s.segments, s.landmarks,
                                s.tracks, HomographyOptions(), &hs);
  std::vector<TexturedPlane> planes;
  auto wrong_size = [](int) { return cv::Mat(10, 10, CV_8UC3); };
  EXPECT_THROW(BuildTexturedPlanes(s.camera, s.poses, s.segments, s.landmarks,
                                   s.tracks, hs, wrong_size, MosaicOptions(),
                                   &planes),
               InputError);
  MosaicOptions bad;
  bad.max_frames_per_plane = 0;
  EXPECT_THROW(bad.Check(), OptionsError);
}

}  // namespace
}  // namespace monomap
