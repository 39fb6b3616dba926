#include "monomap/triangulation/keyframe_adjustment.h"

#include <gtest/gtest.h>

#include <cstdio>

#include "monomap/sim/test_scene.h"
#include "monomap/triangulation/triangulator.h"
#include "monomap/util/angles.h"
#include "monomap/util/error.h"

namespace monomap {
namespace {

// Poses along x, `step_m` apart.
std::vector<Rigid3d> StraightPoses(int n, double step_m) {
  std::vector<Rigid3d> poses;
  for (int i = 0; i < n; ++i) {
    poses.emplace_back(Eigen::Quaterniond::Identity(),
                       Eigen::Vector3d(step_m * i, 0, 0));
  }
  return poses;
}

TEST(KeyframeAdjustmentTest, ShortSequencesKeepTheInterval) {
  KeyframeOptions options;  // interval 3, long above 400 keyframes
  const std::vector<int> k = SelectKeyframes(StraightPoses(11, 0.001), options);
  EXPECT_EQ(k, (std::vector<int>{0, 3, 6, 9, 10}));
  // 1200 frames = 400 keyframes (and the last): not long yet, however
  // slow.
  EXPECT_EQ(SelectKeyframes(StraightPoses(1200, 0.001), options).size(), 401u);
}

TEST(KeyframeAdjustmentTest, LongSequencesAreSpacedByTravel) {
  KeyframeOptions options;
  // 3000 frames at 1.7 mm (0.05 m/s at 30 Hz): 5.1 m, a keyframe per 4 cm
  // (24 frames: 23 are 39.1 mm) instead of 1000 every third frame.
  const std::vector<int> slow =
      SelectKeyframes(StraightPoses(3000, 0.0017), options);
  EXPECT_EQ(slow.front(), 0);
  EXPECT_EQ(slow.back(), 2999);
  EXPECT_EQ(slow[1], 24);
  EXPECT_EQ(slow.size(), 2999u / 24 + 2);
  // At 0.4 m/s (13 mm a frame) the interval still rules: every 4th frame
  // (3 frames are 4 mm short of 4 cm).
  const std::vector<int> fast =
      SelectKeyframes(StraightPoses(3000, 0.0133), options);
  EXPECT_EQ(fast[1], 4);
  // Turning on the spot at 0.4 deg a frame: every interval-th frame (1.2
  // deg) is one, and the last.
  std::vector<Rigid3d> turning = StraightPoses(1500, 0.0);
  for (int i = 0; i < 1500; ++i) {
    turning[i].rotation =
        Eigen::AngleAxisd(DegToRad(0.4 * i), Eigen::Vector3d::UnitY());
  }
  EXPECT_EQ(SelectKeyframes(turning, options).size(), 501u);
  options.interval = 0;
  EXPECT_THROW(SelectKeyframes(turning, options), OptionsError);
}

// A track seen in the given frames.
Track TrackIn(FeatureId id, const std::vector<int>& frames) {
  Track t;
  t.id = id;
  for (int f : frames) t.observations.push_back({f, Eigen::Vector2d(1, 1)});
  return t;
}

TEST(KeyframeAdjustmentTest, CovisibilityCountsKeyframeObservations) {
  const std::vector<int> keyframes = {0, 3, 6, 9, 12};
  // Seen by 5, 3 and 2 keyframes (the last too few to count).
  const std::vector<Track> tracks = {TrackIn(1, {0, 1, 3, 6, 9, 12}),
                                     TrackIn(2, {2, 3, 6, 9}),
                                     TrackIn(3, {0, 3, 4})};
  EXPECT_DOUBLE_EQ(KeyframeCovisibility(tracks, keyframes, 13),
                   (25.0 + 9.0) / (5.0 + 3.0));
  EXPECT_DOUBLE_EQ(KeyframeCovisibility({tracks[2]}, keyframes, 13), 0.0);
}

TEST(KeyframeAdjustmentTest, ThinningKeepsEveryMthKeyframeUpToTheBound) {
  // 301 frames, every third a keyframe (101); 50 tracks each seen by 61
  // consecutive keyframes (183 frames): covisibility 61.
  std::vector<int> keyframes;
  for (int f = 0; f <= 300; f += 3) keyframes.push_back(f);
  std::vector<Track> tracks;
  for (int i = 0; i < 50; ++i) {
    std::vector<int> frames;
    for (int f = 0; f < 183; ++f) frames.push_back(3 * (i % 40) + f);
    tracks.push_back(TrackIn(i, frames));
  }
  ASSERT_NEAR(KeyframeCovisibility(tracks, keyframes, 301), 61.0, 0.5);
  KeyframeOptions options;
  options.max_covisibility = 40.0;
  int thinning = 0;
  const std::vector<int> thin =
      ThinKeyframes(tracks, keyframes, 301, options, &thinning);
  EXPECT_EQ(thinning, 2);
  EXPECT_EQ(thin.front(), 0);
  EXPECT_EQ(thin[1], 6);
  EXPECT_EQ(thin.back(), 300);
  EXPECT_EQ(thin.size(), 51u);
  EXPECT_LE(KeyframeCovisibility(tracks, thin, 301), 40.0);
  EXPECT_GT(KeyframeCovisibility(tracks, thin, 301), 25.0);
  // A tighter bound: every 4th (61 / 4 = 15.3 <= 20 but 61 / 3 > 20).
  options.max_covisibility = 20.0;
  ThinKeyframes(tracks, keyframes, 301, options, &thinning);
  EXPECT_EQ(thinning, 4);
  // Under the bound, or off: unchanged.
  options.max_covisibility = 70.0;
  EXPECT_EQ(ThinKeyframes(tracks, keyframes, 301, options, &thinning),
            keyframes);
  EXPECT_EQ(thinning, 1);
  options.max_covisibility = 0.0;
  EXPECT_EQ(ThinKeyframes(tracks, keyframes, 301, options, &thinning),
            keyframes);
  options.max_covisibility = 2.0;
  EXPECT_THROW(ThinKeyframes(tracks, keyframes, 301, options, &thinning),
               OptionsError);
}

// A slow sequence: 600 frames 2 mm apart, every point seen by 80-200
// frames. Spacing the keyframes by travel (as on a long sequence) gives
// poses nearly as good as every third frame, from a problem a sixth the
// size; thinning them to the default covisibility (as on a short slow
// sequence) less good, but still well below the odometry's error.
TEST(KeyframeAdjustmentTest, TravelSpacedKeyframesKeepThePoses) {
  testing::TestSceneOptions scene_options;
  scene_options.num_frames = 600;
  scene_options.points.step_m = 0.002;
  scene_options.points.num_tracks = 800;
  scene_options.points.min_track_length = 80;
  scene_options.points.max_track_length = 200;
  // At hallway depths: 4 cm is 2-4 % of the distance.
  scene_options.points.min_depth_m = 1.0;
  scene_options.points.max_depth_m = 2.0;
  scene_options.points.pixel_noise_px = 0.3;
  scene_options.seed = 21;
  const testing::TestScene scene = testing::MakeTestScene(scene_options);
  // The simulator's wheel odometry: 1.5 % random error a step.
  testing::OdometryDriftOptions drift;
  drift.translation_noise_fraction = 0.015;
  const std::vector<Rigid3d> odometry =
      testing::SimulateOdometryDrift(scene.world_from_cam, drift);
  std::vector<Landmark> triangulated;
  TriangulateTracks(scene.camera, odometry, scene.tracks,
                    TriangulationOptions(), &triangulated);
  ASSERT_GT(triangulated.size(), 700u);

  auto run = [&](int long_min_keyframes, double max_covisibility,
                 std::vector<Rigid3d>* poses) {
    *poses = odometry;
    std::vector<Landmark> landmarks = triangulated;
    KeyframeOptions options;
    options.long_sequence_min_keyframes = long_min_keyframes;
    options.max_covisibility = max_covisibility;
    // The scene's camera wobbles by 3 degrees every 60 frames: not turns.
    options.long_min_angle_deg = 10.0;
    return BundleAdjustKeyframes(scene.camera, scene.tracks,
                                 BundleAdjustmentOptions(), options, poses,
                                 &landmarks);
  };
  // Mean position error after the best scale about the first camera: one
  // camera cannot see scale, and the odometry's 0.5 % scale error (3 mm
  // at the middle) would hide the shape.
  auto mean_error_mm = [&](const std::vector<Rigid3d>& poses) {
    const Eigen::Vector3d c0 = scene.world_from_cam[0].translation;
    double num = 0.0, den = 0.0;
    for (size_t i = 0; i < poses.size(); ++i) {
      const Eigen::Vector3d p = poses[i].translation - c0;
      num += p.dot(scene.world_from_cam[i].translation - c0);
      den += p.squaredNorm();
    }
    double sum = 0.0;
    for (size_t i = 0; i < poses.size(); ++i) {
      sum += (c0 + num / den * (poses[i].translation - c0) -
              scene.world_from_cam[i].translation)
                 .norm();
    }
    return 1e3 * sum / poses.size();
  };
  std::vector<Rigid3d> every_third, spaced, thinned;
  const BundleAdjustmentReport a = run(0, 0.0, &every_third);
  const BundleAdjustmentReport b = run(150, 0.0, &spaced);
  // Neither long nor spaced, but thinned to covisibility 40 (the scene's
  // 49 is below the default bound; a slow hallway's is 117-176).
  const BundleAdjustmentReport c = run(0, 40.0, &thinned);
  const double odo_mm = mean_error_mm(odometry);
  const double a_mm = mean_error_mm(every_third);
  const double b_mm = mean_error_mm(spaced);
  const double c_mm = mean_error_mm(thinned);
  std::printf(
      "poses %d -> %d / %d, residuals %d -> %d / %d, covisibility %.1f -> "
      "%.1f / %.1f, %.2f -> %.2f / %.2f s; position error odometry %.3f, "
      "every third %.3f, spaced %.3f, thinned %.3f mm\n",
      a.num_poses, b.num_poses, c.num_poses, a.num_residuals, b.num_residuals,
      c.num_residuals, a.covisibility, b.covisibility, c.covisibility,
      a.seconds, b.seconds, c.seconds, odo_mm, a_mm, b_mm, c_mm);
  EXPECT_EQ(a.num_poses, 201);  // every third frame and the last
  EXPECT_EQ(a.keyframe_thinning, 1);
  EXPECT_GT(a.covisibility, 40.0);
  EXPECT_GE(c.keyframe_thinning, 2);
  EXPECT_LE(c.covisibility, 40.0);
  EXPECT_LT(c.num_residuals, a.num_residuals / 2 + 1000);
  EXPECT_EQ(c.termination, "CONVERGENCE");
  // Thinned (every 6th frame): 1.28 mm. Thinning further is not better:
  // every 9th 1.20, 12th 1.34, 21st 1.93 mm.
  EXPECT_LT(c_mm, odo_mm / 2.0);
  EXPECT_LT(c_mm, 1.8 * a_mm);
  // 1.2 m at 4 cm (the wave adds to the travel).
  EXPECT_NEAR(b.num_poses, 31, 3);
  EXPECT_LT(b.num_residuals, a.num_residuals / 4);
  EXPECT_LT(b.covisibility, a.covisibility / 4);
  EXPECT_EQ(b.termination, "CONVERGENCE");
  // Odometry 2.9 mm, every third frame 0.80 mm, spaced 0.94 mm (scale
  // removed).
  EXPECT_LT(a_mm, odo_mm / 3.0);
  EXPECT_LT(b_mm, odo_mm / 2.5);
  EXPECT_LT(b_mm, 1.3 * a_mm);
}

}  // namespace
}  // namespace monomap
