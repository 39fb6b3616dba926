#include "monomap/triangulation/triangulator.h"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <random>

#include "monomap/sim/test_scene.h"
#include "monomap/util/error.h"
#include "monomap/util/stats.h"
#include "monomap/util/random.h"

namespace monomap {
namespace {

TEST(TriangulatorTest, ExactObservationsGiveExactPoints) {
  testing::TestSceneOptions scene_options;
  scene_options.points.num_tracks = 300;
  const testing::TestScene scene = testing::MakeTestScene(scene_options);
  std::vector<Landmark> landmarks;
  const TriangulationReport report =
      TriangulateTracks(scene.camera, scene.world_from_cam, scene.tracks,
                        TriangulationOptions(), &landmarks);
  EXPECT_EQ(report.num_tracks, 300);
  ASSERT_EQ(report.num_points, 300);
  ASSERT_EQ(landmarks.size(), 300u);
  EXPECT_LT(report.mean_reprojection_error_px, 1e-6);
  double max_error = 0.0;
  for (size_t i = 0; i < landmarks.size(); ++i) {
    // Output keeps the track order.
    ASSERT_EQ(landmarks[i].id, static_cast<FeatureId>(i));
    const Landmark& l = landmarks[i];
    max_error = std::max(max_error, (l.x_in_world - scene.points[i]).norm());
    EXPECT_EQ(l.num_observations,
              static_cast<int>(scene.tracks[i].observations.size()));
    EXPECT_GT(l.triangulation_angle_deg, 1.5);
    EXPECT_GT(l.mean_depth_m, 0.29);
    EXPECT_LT(l.mean_depth_m, 0.8);  // distance, not z
    EXPECT_EQ(l.color, Eigen::Vector3f::Zero());
  }
  EXPECT_LT(max_error, 1e-6);
}

TEST(TriangulatorTest, NoisyTracksWithOutliersAndDegenerateCases) {
  testing::TestSceneOptions scene_options;
  scene_options.points.num_tracks = 400;
  scene_options.points.pixel_noise_px = 0.3;
  scene_options.seed = 7;
  testing::TestScene scene = testing::MakeTestScene(scene_options);
  const Camera& camera = scene.camera;
  const int num_clean = 400;
  std::vector<Track> tracks = scene.tracks;
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 0.3);
  FeatureId next_id = 1000;

  // Outliers: tracks that jump to another feature half way (15 px across
  // the motion, so the jump cannot be explained by another depth).
  constexpr int kJumps = 20;
  for (int k = 0; k < kJumps; ++k) {
    Track t = scene.tracks[k];
    t.id = next_id++;
    for (size_t i = t.observations.size() / 2; i < t.observations.size(); ++i) {
      t.observations[i].px += Eigen::Vector2d(0.0, -15.0);
    }
    tracks.push_back(t);
  }
  // Tiny baseline: 3 consecutive frames (6 mm) at 0.5 m: about 0.7 deg.
  constexpr int kTiny = 15;
  for (int k = 0; k < kTiny; ++k) {
    const int frame = 2 * k;
    const Eigen::Vector3d x = scene.world_from_cam[frame + 1] *
                              Eigen::Vector3d(0.05 - 0.01 * k, 0.03, 0.5);
    Track t;
    t.id = next_id++;
    for (int f = frame; f < frame + 3; ++f) {
      const Eigen::Vector2d px =
          camera.ImageFromCam(scene.world_from_cam[f].Inverse() * x) +
          DrawLastFirst<Eigen::Vector2d>(noise, rng);
      t.observations.push_back({f, px});
    }
    tracks.push_back(t);
  }
  // Behind the cameras: consistent observations of points at negative depth.
  constexpr int kBehind = 10;
  for (int k = 0; k < kBehind; ++k) {
    const int frame = 3 * k;
    const Eigen::Vector3d x = scene.world_from_cam[frame] *
                              Eigen::Vector3d(0.04 - 0.01 * k, -0.02, -0.4);
    Track t;
    t.id = next_id++;
    for (int f = frame; f < frame + 20; ++f) {
      t.observations.push_back(
          {f, camera.ImageFromCam(scene.world_from_cam[f].Inverse() * x)});
    }
    tracks.push_back(t);
  }
  // Too short: two observations.
  constexpr int kShort = 12;
  for (int k = 0; k < kShort; ++k) {
    Track t = scene.tracks[k];
    t.id = next_id++;
    t.observations.resize(2);
    tracks.push_back(t);
  }

  std::vector<Landmark> landmarks;
  const TriangulationReport report = TriangulateTracks(
      camera, scene.world_from_cam, tracks, TriangulationOptions(), &landmarks);
  EXPECT_EQ(report.num_tracks, num_clean + kJumps + kTiny + kBehind + kShort);
  EXPECT_EQ(report.num_points, num_clean);
  EXPECT_EQ(report.rejected_reprojection, kJumps);
  EXPECT_EQ(report.rejected_angle, kTiny);
  EXPECT_EQ(report.rejected_cheirality, kBehind);
  EXPECT_EQ(report.rejected_short, kShort);
  EXPECT_EQ(report.rejected_failed, 0);
  // Mean distance of 0.3 px Gaussian residuals is 0.3 sqrt(pi/2) = 0.38 px,
  // a little less after fitting 3 parameters.
  EXPECT_GT(report.mean_reprojection_error_px, 0.25);
  EXPECT_LT(report.mean_reprojection_error_px, 0.42);
  EXPECT_LE(report.median_reprojection_error_px, 0.42);

  // Depth error ~ z^2 sigma / (f B) sqrt(12 / n): z = 0.45 m, sigma = 0.3 px,
  // f = 420 px, B = 3 mm * (n - 1), n ~ 30 for the median track: ~1 mm, i.e.
  // ~0.22% of the depth. Assert half of the points are within 0.5%.
  std::vector<double> relative_errors;
  ASSERT_EQ(landmarks.size(), static_cast<size_t>(num_clean));
  for (const Landmark& l : landmarks) {
    ASSERT_LT(l.id, num_clean);  // only clean tracks survive
    const Eigen::Vector3d& truth = scene.points[l.id];
    relative_errors.push_back((l.x_in_world - truth).norm() / l.mean_depth_m);
  }
  const double median = UpperMedian(relative_errors);
  EXPECT_LT(median, 0.005);
  EXPECT_GT(median, 0.0002);  // the noise is really there
}

TEST(TriangulatorTest, CovarianceMatchesTheActualErrors) {
  // With Gaussian pixel noise sigma, the error e of a refined point is
  // approximately N(0, sigma^2 C): e^T (sigma^2 C)^-1 e is chi-square with
  // 3 degrees of freedom (mean 3, median 2.37; measured 3.03 and 2.33).
  testing::TestSceneOptions scene_options;
  scene_options.points.num_tracks = 600;
  scene_options.points.pixel_noise_px = 0.3;
  scene_options.seed = 11;
  const testing::TestScene scene = testing::MakeTestScene(scene_options);
  std::vector<Landmark> landmarks;
  TriangulateTracks(scene.camera, scene.world_from_cam, scene.tracks,
                    TriangulationOptions(), &landmarks);
  ASSERT_GT(landmarks.size(), 500u);
  std::vector<double> mahalanobis2, anisotropy;
  const double var =
      scene_options.points.pixel_noise_px * scene_options.points.pixel_noise_px;
  for (const Landmark& l : landmarks) {
    const Eigen::Matrix3d c = var * l.covariance_m2_per_px2;
    ASSERT_GT(c.determinant(), 0.0);
    const Eigen::Vector3d e = l.x_in_world - scene.points[l.id];
    mahalanobis2.push_back(e.dot(c.ldlt().solve(e)));
    // Depth is the loose direction: largest / smallest eigenvalue.
    const Eigen::Vector3d ev =
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(c).eigenvalues();
    anisotropy.push_back(std::sqrt(ev(2) / ev(0)));
  }
  double mean = 0.0;
  for (double m : mahalanobis2) mean += m;
  mean /= mahalanobis2.size();
  EXPECT_GT(mean, 2.4);
  EXPECT_LT(mean, 3.8);
  EXPECT_GT(UpperMedian(mahalanobis2), 1.8);
  EXPECT_LT(UpperMedian(mahalanobis2), 3.0);
  EXPECT_GT(UpperMedian(anisotropy), 5.0);  // measured 19
}

TEST(TriangulatorTest, LinearOnlyIsWorseThanRefined) {
  testing::TestSceneOptions scene_options;
  scene_options.points.num_tracks = 300;
  scene_options.points.pixel_noise_px = 0.5;
  const testing::TestScene scene = testing::MakeTestScene(scene_options);
  TriangulationOptions options;
  std::vector<Landmark> refined, linear;
  const TriangulationReport r1 = TriangulateTracks(
      scene.camera, scene.world_from_cam, scene.tracks, options, &refined);
  options.nonlinear_refinement = false;
  const TriangulationReport r2 = TriangulateTracks(
      scene.camera, scene.world_from_cam, scene.tracks, options, &linear);
  // The refinement minimises exactly this error, so it can only lower it.
  EXPECT_LT(r1.mean_reprojection_error_px, r2.mean_reprojection_error_px);
}

TEST(TriangulatorTest, RejectsBadInput) {
  const testing::TestScene scene =
      testing::MakeTestScene(testing::TestSceneOptions());
  std::vector<Landmark> landmarks;
  std::vector<Rigid3d> too_few(scene.world_from_cam.begin(),
                               scene.world_from_cam.begin() + 10);
  EXPECT_THROW(TriangulateTracks(scene.camera, too_few, scene.tracks,
                                 TriangulationOptions(), &landmarks),
               InputError);
  TriangulationOptions bad;
  bad.min_track_length = 1;
  EXPECT_THROW(bad.Check(), OptionsError);
  bad = TriangulationOptions();
  bad.max_reprojection_error_px = -1.0;
  EXPECT_THROW(TriangulateTracks(scene.camera, scene.world_from_cam,
                                 scene.tracks, bad, &landmarks),
               OptionsError);
}

}  // namespace
}  // namespace monomap
