#include "monomap/texture/image_plane_homography.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "monomap/geometry/homography.h"
#include "monomap/sim/test_scene.h"
#include "monomap/util/error.h"
#include "monomap/util/random.h"

namespace monomap {
namespace {

Camera TestCamera() {
  Camera c;
  c.width = 320;
  c.height = 240;
  c.fx = 280;
  c.fy = 282;
  c.cx = 158.3;
  c.cy = 121.1;
  c.distortion = {-0.25, 0.08, 0.001, -0.0008, 0.0};
  return c;
}

std::vector<Rigid3d> TestPoses(int n) {
  std::vector<Rigid3d> poses;
  for (int i = 0; i < n; ++i) {
    const double a = 6.283185307179586 * i / n;
    const Eigen::Vector3d eye(0.3 + 0.12 * std::cos(a),
                              0.2 + 0.08 * std::sin(a),
                              0.5 + 0.05 * std::sin(2 * a));
    const Eigen::Vector3d target(0.3 + 0.03 * std::sin(a), 0.2, 0.0);
    poses.push_back(testing::LookAt(eye, target, Eigen::Vector3d::UnitY()));
  }
  return poses;
}

// One 0.6 x 0.4 m plane at z = 0 (segment id `plane_id`) seen by `frames`
// cameras, with `count` features (ids from `first_id`) observed from the
// true poses.
using OnePlaneScene = testing::TestScene;

OnePlaneScene MakeOnePlaneScene(int frames, int plane_id, int count,
                                FeatureId first_id, uint32_t seed) {
  testing::TestSceneOptions o;
  o.layout = testing::TestLayout::kDesk;
  o.camera = TestCamera();
  o.world_from_cam = TestPoses(frames);
  o.desk.plane_id = plane_id;
  o.desk.num_features = count;
  o.desk.first_feature_id = first_id;
  o.desk.feature_seed = seed;
  return testing::MakeTestScene(o);
}

// The homographies of `scene` for the given poses (the true ones or not).
HomographyReport ComputeFor(const OnePlaneScene& scene,
                            const std::vector<Rigid3d>& poses,
                            const HomographyOptions& options,
                            std::vector<ImagePlaneHomography>* hs) {
  return ComputeImagePlaneHomographies(scene.camera, poses, scene.segments,
                                       scene.landmarks, scene.tracks, options,
                                       hs);
}

TEST(ImagePlaneHomographyTest, MatchesAnalyticProjectionForExactPoses) {
  const OnePlaneScene scene = MakeOnePlaneScene(10, 3, 50, 100, 7);
  std::vector<ImagePlaneHomography> hs;
  const HomographyReport report =
      ComputeFor(scene, scene.world_from_cam, HomographyOptions(), &hs);
  ASSERT_EQ(report.num_homographies, 10);
  EXPECT_EQ(report.num_checked, 10);
  EXPECT_EQ(report.num_refined, 0);
  EXPECT_LT(report.median_residual_before_px, 1e-6);

  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const Eigen::Matrix3d k = scene.camera.K();
  for (const auto& h : hs) {
    EXPECT_EQ(h.plane_id, 3);
    EXPECT_GT(h.visible_fraction, 0.5);
    EXPECT_GT(h.num_features, 20);
    EXPECT_LT(h.before.max, 1e-6);
    EXPECT_FALSE(h.refined);
    // Plane resolution is about f / height.
    EXPECT_NEAR(h.pixels_per_meter, 280.0 / 0.5, 150.0);
    const Rigid3d cam_from_world = scene.world_from_cam[h.frame].Inverse();
    double max_err = 0.0;
    for (int i = 0; i < 100; ++i) {
      const Eigen::Vector2d st =
          Eigen::Vector2d(0.6, 0.4).cwiseProduct(
              DrawLastFirst<Eigen::Vector2d>(u, rng));
      const Eigen::Vector3d x =
          cam_from_world * scene.segments[0].frame.ToWorld(st);
      const Eigen::Vector2d expected = (k * x).hnormalized();
      max_err = std::max(
          max_err, (ApplyHomography(h.pixel_from_plane, st) - expected).norm());
    }
    EXPECT_LT(max_err, 1e-6) << "frame " << h.frame;
  }
}

TEST(ImagePlaneHomographyTest, RefinesWhenPoseIsOff) {
  // Observations from the true poses, homographies from perturbed ones.
  const OnePlaneScene scene = MakeOnePlaneScene(8, 0, 60, 0, 3);
  std::vector<Rigid3d> wrong = scene.world_from_cam;
  for (size_t i = 0; i < wrong.size(); ++i) {
    wrong[i] =
        wrong[i] * Rigid3d(QuaternionFromRotationVector({0.008, -0.006, 0.004}),
                           Eigen::Vector3d(0.01, -0.005, 0.0));
  }
  std::vector<ImagePlaneHomography> hs;
  const HomographyReport report =
      ComputeFor(scene, wrong, HomographyOptions(), &hs);
  ASSERT_EQ(report.num_homographies, 8);
  EXPECT_EQ(report.num_refined, 8);
  EXPECT_GT(report.median_residual_before_px, 2.0);
  EXPECT_LT(report.median_residual_after_px, 0.01);
  for (const auto& h : hs) {
    EXPECT_TRUE(h.refined);
    EXPECT_LT(h.after.max, 0.05);
    EXPECT_LT(h.residual_after_px, h.residual_before_px);
  }

  // Without refinement the residual stays.
  HomographyOptions no_refine;
  no_refine.refine = false;
  const HomographyReport r2 = ComputeFor(scene, wrong, no_refine, &hs);
  EXPECT_EQ(r2.num_refined, 0);
  EXPECT_GT(r2.median_residual_after_px, 2.0);
}

// Landmarks inside the plane fit's band but off the plane (keys on a
// keyboard on a desk) are displaced by parallax; they must not be taken
// for a homography error and warp the texture away from the poses.
TEST(ImagePlaneHomographyTest, IgnoresParallaxOfLandmarksOffThePlane) {
  OnePlaneScene scene = MakeOnePlaneScene(10, 0, 40, 0, 3);
  // Twice as many 15 mm above the plane (towards the cameras), labelled as
  // the plane's.
  PlaneSegment raised =
      testing::HorizontalRectangle(0, 0.0, 0.0, 0.015, 0.6, 0.4);
  testing::MakePlaneFeatures(scene.camera, scene.world_from_cam, 80, 1000, 4, &raised,
                             &scene.landmarks, &scene.tracks);
  for (FeatureId id : raised.inlier_ids)
    scene.segments[0].inlier_ids.push_back(id);

  std::vector<ImagePlaneHomography> hs;
  const HomographyReport report =
      ComputeFor(scene, scene.world_from_cam, HomographyOptions(), &hs);
  ASSERT_EQ(report.num_homographies, 10);
  EXPECT_EQ(report.num_refined, 0);
  EXPECT_LT(report.median_residual_before_px, 1e-6);
  for (const auto& h : hs) {
    EXPECT_FALSE(h.refined);
    // The raised landmarks are left out, the ones on the plane kept (a
    // raised one seen almost along the normal has under 0.5 px parallax).
    EXPECT_GT(h.num_features, 20);
    EXPECT_LE(h.num_features, 45);
  }

  // Taking every landmark of the plane, the parallax (several pixels at
  // 0.5 m) looks like a homography error and triggers refinement.
  HomographyOptions all;
  all.max_feature_parallax_px = 1e9;
  const HomographyReport r2 = ComputeFor(scene, scene.world_from_cam, all, &hs);
  EXPECT_GT(r2.median_residual_before_px, 1.0);
  EXPECT_GT(r2.num_refined, 0);
}

TEST(ImagePlaneHomographyTest, SkipsPlanesOutOfView) {
  const Camera camera = TestCamera();
  const auto poses = TestPoses(4);
  // A plane far to the side and one behind the cameras.
  std::vector<PlaneSegment> segments = {
      testing::HorizontalRectangle(0, 5.0, 5.0, 0.0, 0.3, 0.3),
      testing::HorizontalRectangle(1, 0.0, 0.0, 1.5, 0.6, 0.4)};
  std::vector<ImagePlaneHomography> hs;
  const HomographyReport report = ComputeImagePlaneHomographies(
      camera, poses, segments, {}, {}, HomographyOptions(), &hs);
  EXPECT_EQ(report.num_homographies, 0);
}

TEST(ImagePlaneHomographyTest, OptionsCheck) {
  HomographyOptions o;
  EXPECT_NO_THROW(o.Check());
  o.min_features_to_refine = 2;
  EXPECT_THROW(o.Check(), OptionsError);
  o = HomographyOptions();
  o.min_visible_fraction = 1.5;
  EXPECT_THROW(o.Check(), OptionsError);
  o = HomographyOptions();
  o.max_feature_parallax_px = 0.0;
  EXPECT_THROW(o.Check(), OptionsError);
}

}  // namespace
}  // namespace monomap
