#include "monomap/triangulation/bundle_adjustment.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>

#include "monomap/geometry/pose2d.h"
#include "monomap/sim/test_scene.h"
#include "monomap/triangulation/triangulator.h"
#include "monomap/util/angles.h"
#include "monomap/util/error.h"
#include "monomap/util/random.h"
#include "monomap/util/stats.h"

namespace monomap {
namespace {

struct Errors {
  double median_point_m = 0.0;
  double median_point_scaled_m = 0.0;  // after the best scale about cam 0
  double mean_position_m = 0.0;
  double mean_rotation_deg = 0.0;
};

// Errors against the truth. The gauge is fixed by the first pose, which the
// odometry shares with the truth; the scale is kept by the odometry (0.5%
// off), so the "scaled" figure removes the best scale about the first camera
// centre to show the shape error alone.
Errors Compare(const testing::TestScene& scene,
               const std::vector<Rigid3d>& world_from_cam,
               const std::vector<Landmark>& landmarks) {
  Errors e;
  const Eigen::Vector3d c0 = scene.world_from_cam[0].translation;
  double num = 0.0, den = 0.0;
  for (const Landmark& l : landmarks) {
    const Eigen::Vector3d a = l.x_in_world - c0;
    const Eigen::Vector3d b = scene.points[l.id] - c0;
    num += a.dot(b);
    den += a.squaredNorm();
  }
  const double s = num / den;
  std::vector<double> raw, scaled;
  for (const Landmark& l : landmarks) {
    const Eigen::Vector3d& truth = scene.points[l.id];
    raw.push_back((l.x_in_world - truth).norm());
    scaled.push_back((c0 + s * (l.x_in_world - c0) - truth).norm());
  }
  e.median_point_m = UpperMedian(raw);
  e.median_point_scaled_m = UpperMedian(scaled);
  for (size_t i = 0; i < world_from_cam.size(); ++i) {
    e.mean_position_m +=
        (world_from_cam[i].translation - scene.world_from_cam[i].translation)
            .norm();
    e.mean_rotation_deg += RadToDeg(AngleBetween(
        world_from_cam[i].rotation, scene.world_from_cam[i].rotation));
  }
  e.mean_position_m /= world_from_cam.size();
  e.mean_rotation_deg /= world_from_cam.size();
  return e;
}

// A synthetic scene whose tracks carry 0.3 px of pixel noise.
testing::TestScene NoisyScene(int num_tracks, uint64_t seed) {
  testing::TestSceneOptions options;
  options.points.num_tracks = num_tracks;
  options.points.pixel_noise_px = 0.3;
  options.seed = seed;
  return testing::MakeTestScene(options);
}

TEST(BundleAdjustmentTest, CorrectsOdometryDrift) {
  const testing::TestScene scene = NoisyScene(400, 11);
  std::vector<Rigid3d> poses = testing::SimulateOdometryDrift(
      scene.world_from_cam, testing::OdometryDriftOptions());

  std::vector<Landmark> landmarks;
  const TriangulationReport tri = TriangulateTracks(
      scene.camera, poses, scene.tracks, TriangulationOptions(), &landmarks);
  ASSERT_GT(tri.num_points, 300);
  const Errors before = Compare(scene, poses, landmarks);

  const BundleAdjustmentReport report =
      BundleAdjust(scene.camera, scene.tracks, BundleAdjustmentOptions(),
                   &poses, &landmarks);
  const Errors after = Compare(scene, poses, landmarks);
  std::printf(
      "tri %d pts, err %.3f px; BA rms %.3f -> %.3f px, median %.3f -> %.3f, "
      "%d it, %s, %.3f s, dropped %d\n"
      "point median %.3f -> %.3f mm, scaled %.3f -> %.3f mm\n"
      "position %.3f -> %.3f mm, rotation %.4f -> %.4f deg\n",
      tri.num_points, tri.mean_reprojection_error_px,
      report.initial_rms_error_px, report.final_rms_error_px,
      report.initial_median_error_px, report.final_median_error_px,
      report.iterations, report.termination.c_str(), report.seconds,
      report.num_dropped, 1e3 * before.median_point_m,
      1e3 * after.median_point_m, 1e3 * before.median_point_scaled_m,
      1e3 * after.median_point_scaled_m, 1e3 * before.mean_position_m,
      1e3 * after.mean_position_m, before.mean_rotation_deg,
      after.mean_rotation_deg);

  EXPECT_EQ(report.num_poses, 60);
  EXPECT_EQ(report.num_points, tri.num_points);
  EXPECT_EQ(report.num_priors, 59);
  EXPECT_LT(report.final_rms_error_px, 0.5);
  EXPECT_LT(report.final_rms_error_px, report.initial_rms_error_px);
  EXPECT_EQ(report.termination, "CONVERGENCE");
  EXPECT_EQ(report.num_dropped, 0);
  EXPECT_EQ(static_cast<int>(landmarks.size()), tri.num_points);
  // The first pose is the gauge: untouched.
  EXPECT_LT((poses[0].translation - scene.world_from_cam[0].translation).norm(),
            1e-12);
  EXPECT_GT(report.mean_pose_change_m, 0.0);
  // Drift makes the triangulated points ~5 mm off (median), BA brings them
  // to ~1.4 mm (the 0.5% scale error of the odometry, unobservable, is most
  // of what is left): assert a factor 2.5 on both figures.
  EXPECT_LT(after.median_point_m, before.median_point_m / 2.5);
  EXPECT_LT(after.median_point_scaled_m, before.median_point_scaled_m / 2.5);
  EXPECT_LT(after.median_point_m, 0.002);
  // Poses: ~1.7 mm / 0.11 deg mean error before, ~0.4 mm / 0.03 deg after.
  EXPECT_LT(after.mean_position_m, before.mean_position_m / 2.0);
  EXPECT_LT(after.mean_rotation_deg, before.mean_rotation_deg / 2.0);
}

// Median over frames of the rotation of cam_i_from_cam_{i+1} against the
// truth's (degrees): how well the motion from frame to frame is known.
double MedianStepRotationErrorDeg(const testing::TestScene& scene,
                                  const std::vector<Rigid3d>& world_from_cam) {
  std::vector<double> errors;
  for (size_t i = 0; i + 1 < world_from_cam.size(); ++i) {
    const Rigid3d step = world_from_cam[i].Inverse() * world_from_cam[i + 1];
    const Rigid3d truth =
        scene.world_from_cam[i].Inverse() * scene.world_from_cam[i + 1];
    errors.push_back(AngleBetween(step.rotation, truth.rotation) * 180.0 /
                     M_PI);
  }
  return UpperMedian(errors);
}

// Odometry whose error is mostly per-frame jitter that does not accumulate
// (0.05 deg per axis on each pose, on top of a small drift): the per-step
// priors, which treat the odometry's error as independent increments, hold
// the poses to that jitter. Loose per-step priors plus span priors let the
// images set the motion from frame to frame while the spans hold the drift.
TEST(BundleAdjustmentTest, SpanPriorsLetTheImagesRemoveOdometryJitter) {
  const testing::TestScene scene = NoisyScene(400, 11);
  std::vector<Rigid3d> odometry = testing::SimulateOdometryDrift(
      scene.world_from_cam, testing::OdometryDriftOptions());
  std::mt19937_64 rng(5);
  std::normal_distribution<double> jitter(0.0, DegToRad(0.05));
  for (size_t i = 1; i < odometry.size(); ++i) {
    const auto w = DrawLastFirst<Eigen::Vector3d>(jitter, rng);
    odometry[i] = odometry[i] * Rigid3d(QuaternionFromRotationVector(w),
                                        Eigen::Vector3d::Zero());
  }
  std::vector<Landmark> triangulated;
  TriangulateTracks(scene.camera, odometry, scene.tracks,
                    TriangulationOptions(), &triangulated);
  const double jitter_before = MedianStepRotationErrorDeg(scene, odometry);

  auto adjust = [&](const BundleAdjustmentOptions& options,
                    BundleAdjustmentReport* report) {
    std::vector<Rigid3d> poses = odometry;
    std::vector<Landmark> landmarks = triangulated;
    *report =
        BundleAdjust(scene.camera, scene.tracks, options, &poses, &landmarks);
    return poses;
  };
  BundleAdjustmentReport per_step_report, span_report;
  const std::vector<Rigid3d> per_step =
      adjust(BundleAdjustmentOptions(), &per_step_report);
  BundleAdjustmentOptions span_options;
  span_options.rotation_sigma_floor_deg = 0.2;
  span_options.span_poses = 10;
  span_options.span_rotation_sigma_deg = 0.08;
  const std::vector<Rigid3d> span = adjust(span_options, &span_report);

  const double step_per_step = MedianStepRotationErrorDeg(scene, per_step);
  const double step_span = MedianStepRotationErrorDeg(scene, span);
  const Errors e_per_step = Compare(scene, per_step, triangulated);
  const Errors e_span = Compare(scene, span, triangulated);
  std::printf(
      "frame-to-frame rotation error: odometry %.4f, per-step priors %.4f, "
      "span priors %.4f deg; mean rotation error %.4f / %.4f deg\n",
      jitter_before, step_per_step, step_span, e_per_step.mean_rotation_deg,
      e_span.mean_rotation_deg);
  EXPECT_EQ(per_step_report.num_span_priors, 0);
  EXPECT_EQ(span_report.num_span_priors, 50);  // 60 poses, spans of 10
  EXPECT_EQ(span_report.num_priors, 59);
  // Measured 0.074 -> 0.026 deg from frame to frame (the odometry: 0.105).
  EXPECT_LT(step_span, step_per_step / 2.0);
  // The absolute orientation is not what span priors improve on this short
  // sideways sequence: mean 0.071 -> 0.084 deg (spans of 5: 0.062). Bounded
  // so that a regression shows.
  EXPECT_LT(e_span.mean_rotation_deg, 1.3 * e_per_step.mean_rotation_deg);
  EXPECT_LT(e_span.mean_rotation_deg, 0.1);
}

// Triangulates `tracks` with `camera` against the odometry, adjusts, and
// compares with the scene's truth.
Errors AdjustWithLens(const testing::TestScene& scene, const Camera& camera,
                      const std::vector<Track>& tracks,
                      const std::vector<Rigid3d>& odometry,
                      const BundleAdjustmentOptions& options,
                      BundleAdjustmentReport* report = nullptr) {
  std::vector<Rigid3d> poses = odometry;
  std::vector<Landmark> landmarks;
  TriangulateTracks(camera, poses, tracks, TriangulationOptions(), &landmarks);
  const BundleAdjustmentReport r =
      BundleAdjust(camera, tracks, options, &poses, &landmarks);
  if (report) *report = r;
  return Compare(scene, poses, landmarks);
}

// The scene adjusted with its true lens (no self-calibration), and with
// `given` under options `a` and under options `b`.
struct LensTrials {
  Errors with_true, with_a, with_b;
  BundleAdjustmentReport report_a, report_b;
};
LensTrials AdjustThreeWays(const testing::TestScene& scene, const Camera& given,
                           const std::vector<Rigid3d>& odometry,
                           const BundleAdjustmentOptions& a,
                           const BundleAdjustmentOptions& b) {
  LensTrials t;
  t.with_true = AdjustWithLens(scene, scene.camera, scene.tracks, odometry, {});
  t.with_a =
      AdjustWithLens(scene, given, scene.tracks, odometry, a, &t.report_a);
  t.with_b =
      AdjustWithLens(scene, given, scene.tracks, odometry, b, &t.report_b);
  return t;
}

// A calibration whose k1 is off by 0.02 (~1.5 px at 300 px from the centre)
// bends the adjusted poses; refining the distortion in the adjustment finds
// the lens again and straightens them.
TEST(BundleAdjustmentTest, RefinesAWrongDistortion) {
  const testing::TestScene scene = NoisyScene(500, 13);
  Camera wrong = scene.camera;
  wrong.distortion[0] += 0.02;
  const std::vector<Rigid3d> odometry = testing::SimulateOdometryDrift(
      scene.world_from_cam, testing::OdometryDriftOptions());
  auto run = [&](bool refine, BundleAdjustmentReport* report) {
    BundleAdjustmentOptions options;
    options.refine_distortion = refine;
    return AdjustWithLens(scene, wrong, scene.tracks, odometry, options,
                          report);
  };
  BundleAdjustmentReport fixed_report, refined_report;
  const Errors fixed = run(false, &fixed_report);
  const Errors refined = run(true, &refined_report);
  std::printf(
      "fixed lens: rms %.3f px, rotation %.4f deg, points %.3f mm\n"
      "refined: k1 %.4f (true %.4f), rms %.3f px, rotation %.4f deg, "
      "points %.3f mm\n",
      fixed_report.final_rms_error_px, fixed.mean_rotation_deg,
      1e3 * fixed.median_point_m, refined_report.distortion[0],
      scene.camera.distortion[0], refined_report.final_rms_error_px,
      refined.mean_rotation_deg, 1e3 * refined.median_point_m);
  // Without refinement the distortion stays wrong and is reported as is.
  EXPECT_EQ(fixed_report.distortion, wrong.distortion);
  EXPECT_NEAR(refined_report.distortion[0], scene.camera.distortion[0], 0.005);
  // Both fit the 0.3 px noise (0.42 px RMS per observation): the poses and
  // points absorb the wrong lens, so the residual does not show it (fixed:
  // 0.42 px, 0.41 deg, 12 mm; refined: 0.41 px, 0.06 deg, 3.7 mm).
  EXPECT_LT(refined_report.final_rms_error_px, 0.5);
  EXPECT_LT(refined.mean_rotation_deg, 0.3 * fixed.mean_rotation_deg);
  EXPECT_LT(refined.median_point_m, 0.5 * fixed.median_point_m);
}

// A scene seen through a fisheye (equidistant) lens, 0.3 px noise.
testing::TestScene FisheyeScene() {
  testing::TestSceneOptions options;
  options.points.num_tracks = 500;
  options.points.pixel_noise_px = 0.3;
  options.seed = 13;
  Camera fisheye = testing::SyntheticCamera();
  fisheye.fx = fisheye.fy = 300.0;
  fisheye.model = LensModel::kEquidistant;
  fisheye.distortion = {0.02, -0.004, 0.001, -0.0002, 0.0};
  options.camera = fisheye;
  return testing::MakeTestScene(options);
}

// The same with a fisheye (equidistant) lens: triangulation and adjustment
// project through the camera's own model, and refining k1..k4 finds a
// wrong k1 again while k5 stays 0.
TEST(BundleAdjustmentTest, FisheyeLensAdjustsAndRefines) {
  const testing::TestScene scene = FisheyeScene();
  const Camera& fisheye = scene.camera;
  const std::vector<Rigid3d> odometry = testing::SimulateOdometryDrift(
      scene.world_from_cam, testing::OdometryDriftOptions());
  BundleAdjustmentOptions ba;
  BundleAdjustmentReport right_report, refined_report;
  const Errors right =
      AdjustWithLens(scene, fisheye, scene.tracks, odometry, ba, &right_report);
  Camera wrong = fisheye;
  wrong.distortion[0] += 0.03;
  ba.refine_distortion = true;
  const Errors refined =
      AdjustWithLens(scene, wrong, scene.tracks, odometry, ba, &refined_report);
  // k1..k4 trade off against each other: compare what the lenses do, the
  // pixel where each images the true ray of a pixel, over the region the
  // tracks cover (440 x 360 px about the centre).
  Camera adjusted = fisheye;
  adjusted.distortion = refined_report.distortion;
  double wrong_px = 0, adjusted_px = 0;
  for (double du = -220; du <= 220; du += 20) {
    for (double dv = -180; dv <= 180; dv += 20) {
      const Eigen::Vector2d px(fisheye.cx + du, fisheye.cy + dv);
      const Eigen::Vector3d ray = fisheye.NormalizedFromImage(px).homogeneous();
      wrong_px = std::max(wrong_px, (wrong.ImageFromCam(ray) - px).norm());
      adjusted_px =
          std::max(adjusted_px, (adjusted.ImageFromCam(ray) - px).norm());
    }
  }
  std::printf(
      "fisheye: rms %.3f px, rotation %.4f deg, points %.3f mm; refined k1 "
      "%.4f (true %.4f), lens off by %.2f px (wrong: %.2f px), rms %.3f px, "
      "points %.3f mm\n",
      right_report.final_rms_error_px, right.mean_rotation_deg,
      1e3 * right.median_point_m, refined_report.distortion[0],
      fisheye.distortion[0], adjusted_px, wrong_px,
      refined_report.final_rms_error_px, 1e3 * refined.median_point_m);
  // Measured: wrong lens 7.3 px, refined 0.53 px (at the corners of the
  // region, where few tracks reach).
  EXPECT_GT(wrong_px, 5.0);
  EXPECT_LT(adjusted_px, 1.0);
  // The 0.3 px noise gives 0.42 px RMS per observation with the right lens
  // (as with plumb_bob above); a plumb_bob projection of these tracks would
  // be off by tens of pixels at the rim.
  EXPECT_LT(right_report.final_rms_error_px, 0.5);
  EXPECT_LT(right.mean_rotation_deg, 0.1);
  EXPECT_LT(right.median_point_m, 0.01);
  EXPECT_NEAR(refined_report.distortion[0], fisheye.distortion[0], 0.01);
  EXPECT_EQ(refined_report.distortion[4], 0.0);
  EXPECT_LT(refined_report.final_rms_error_px, 0.5);
}

// A calibration right in the middle of the image but off at its rim (k3
// off by 0.02: 0.05 px at 200 px from the centre, 0.24 px at 250, 2.3 px
// at 350), as one fitted on checkerboard views that never reach the
// corners. Bundle adjustment on every observation bends the poses to fit
// the rim; leaving out the observations beyond 250 px keeps them straight.
TEST(BundleAdjustmentTest, ObservationsBeyondTheCalibratedRadiusLeftOut) {
  const testing::TestScene scene = NoisyScene(500, 17);
  Camera wrong = scene.camera;
  wrong.distortion[4] += 0.02;
  const std::vector<Rigid3d> odometry = testing::SimulateOdometryDrift(
      scene.world_from_cam, testing::OdometryDriftOptions());
  auto run = [&](const std::vector<Track>& tracks) {
    return AdjustWithLens(scene, wrong, tracks, odometry,
                          BundleAdjustmentOptions());
  };
  int64_t dropped = 0;
  const std::vector<Track> inner =
      ObservationsWithinRadius(scene.tracks, wrong, 250.0, &dropped);
  int64_t total = 0;
  for (const Track& t : scene.tracks) total += t.observations.size();
  for (const Track& t : inner) {
    for (const Observation& o : t.observations) {
      ASSERT_LE((o.px - Eigen::Vector2d(wrong.cx, wrong.cy)).norm(), 250.0);
    }
  }
  const Errors all = run(scene.tracks);
  const Errors central = run(inner);
  std::printf(
      "all observations: rotation %.4f deg, points %.3f mm\n"
      "within 250 px (%lld of %lld left out): rotation %.4f deg, points "
      "%.3f mm\n",
      all.mean_rotation_deg, 1e3 * all.median_point_m,
      static_cast<long long>(dropped), static_cast<long long>(total),
      central.mean_rotation_deg, 1e3 * central.median_point_m);
  // A few rim observations bend everything: 4 % of them left out take the
  // rotation error from 0.15 to 0.07 deg and the points from 3.8 to 1.3 mm.
  EXPECT_GT(dropped, 0);
  EXPECT_LT(dropped, total / 10);
  EXPECT_LT(central.mean_rotation_deg, 0.5 * all.mean_rotation_deg);
  EXPECT_LT(central.median_point_m, 0.5 * all.median_point_m);
}

// The automatic choice of the linear solver (iterative for points seen by
// many frames) must not change the solution: preconditioned CG solves each
// step only approximately, but LM converges to the same minimum.
TEST(BundleAdjustmentTest, IterativeSchurReachesTheDirectSolution) {
  const testing::TestScene scene = NoisyScene(300, 5);
  const std::vector<Rigid3d> odometry = testing::SimulateOdometryDrift(
      scene.world_from_cam, testing::OdometryDriftOptions());
  std::vector<Landmark> triangulated;
  TriangulateTracks(scene.camera, odometry, scene.tracks,
                    TriangulationOptions(), &triangulated);

  auto run = [&](double min_covisibility, std::vector<Rigid3d>* poses,
                 std::vector<Landmark>* landmarks) {
    *poses = odometry;
    *landmarks = triangulated;
    BundleAdjustmentOptions options;
    options.iterative_schur_min_covisibility = min_covisibility;
    return BundleAdjust(scene.camera, scene.tracks, options, poses, landmarks);
  };
  std::vector<Rigid3d> direct_poses, cg_poses;
  std::vector<Landmark> direct_points, cg_points;
  const BundleAdjustmentReport direct = run(0.0, &direct_poses, &direct_points);
  // Below the scene's covisibility: the automatic choice takes CG.
  const BundleAdjustmentReport cg =
      run(0.5 * direct.covisibility, &cg_poses, &cg_points);
  EXPECT_GT(direct.covisibility, 2.0);
  EXPECT_EQ(direct.linear_solver, "DENSE_SCHUR");
  EXPECT_EQ(cg.linear_solver, "ITERATIVE_SCHUR");
  EXPECT_EQ(cg.covisibility, direct.covisibility);
  EXPECT_NEAR(cg.final_rms_error_px, direct.final_rms_error_px, 1e-3);
  ASSERT_EQ(cg_points.size(), direct_points.size());
  double max_pose_diff = 0.0, max_point_diff = 0.0;
  for (size_t i = 0; i < cg_poses.size(); ++i) {
    max_pose_diff = std::max(
        max_pose_diff,
        (cg_poses[i].translation - direct_poses[i].translation).norm());
  }
  for (size_t i = 0; i < cg_points.size(); ++i) {
    max_point_diff = std::max(
        max_point_diff,
        (cg_points[i].x_in_world - direct_points[i].x_in_world).norm());
  }
  // Both solutions are ~1 mm from the truth and stop within Ceres'
  // function tolerance of the minimum, where they agree to ~1 um (poses)
  // and ~30 um (the worst point). With Ceres' default CG tolerance (eta
  // 0.1) the poses differed by 11 um.
  EXPECT_LT(max_pose_diff, 5e-6);
  EXPECT_LT(max_point_diff, 1e-4);
}

TEST(BundleAdjustmentTest, DisabledLeavesInputUnchanged) {
  const testing::TestScene scene =
      NoisyScene(100, testing::TestSceneOptions().seed);
  std::vector<Rigid3d> poses = testing::SimulateOdometryDrift(
      scene.world_from_cam, testing::OdometryDriftOptions());
  std::vector<Landmark> landmarks;
  TriangulateTracks(scene.camera, poses, scene.tracks, TriangulationOptions(),
                    &landmarks);
  const std::vector<Rigid3d> poses_in = poses;
  const std::vector<Landmark> landmarks_in = landmarks;
  BundleAdjustmentOptions options;
  options.enabled = false;
  const BundleAdjustmentReport report =
      BundleAdjust(scene.camera, scene.tracks, options, &poses, &landmarks);
  EXPECT_EQ(report.termination, "disabled");
  EXPECT_GT(report.initial_rms_error_px, 0.3);
  EXPECT_EQ(report.final_rms_error_px, report.initial_rms_error_px);
  ASSERT_EQ(landmarks.size(), landmarks_in.size());
  for (size_t i = 0; i < poses.size(); ++i) {
    EXPECT_EQ(poses[i].translation, poses_in[i].translation);
  }
  for (size_t i = 0; i < landmarks.size(); ++i) {
    EXPECT_EQ(landmarks[i].x_in_world, landmarks_in[i].x_in_world);
  }
}

TEST(BundleAdjustmentTest, RejectsBadInput) {
  testing::TestSceneOptions scene_options;
  scene_options.points.num_tracks = 20;
  const testing::TestScene scene = testing::MakeTestScene(scene_options);
  std::vector<Rigid3d> poses = scene.world_from_cam;
  std::vector<Landmark> landmarks(1);
  landmarks[0].id = 12345;  // no such track
  EXPECT_THROW(BundleAdjust(scene.camera, scene.tracks,
                            BundleAdjustmentOptions(), &poses, &landmarks),
               InputError);
  BundleAdjustmentOptions bad;
  bad.loss = "tukey";
  EXPECT_THROW(bad.Check(), OptionsError);
  bad = BundleAdjustmentOptions();
  bad.num_threads = 0;
  EXPECT_THROW(bad.Check(), OptionsError);
  bad = BundleAdjustmentOptions();
  bad.span_poses = -1;
  EXPECT_THROW(bad.Check(), OptionsError);
  bad = BundleAdjustmentOptions();
  bad.span_rotation_sigma_deg = 0.0;
  EXPECT_THROW(bad.Check(), OptionsError);
  bad = BundleAdjustmentOptions();
  bad.outlier_threshold_px = -1.0;
  EXPECT_THROW(bad.Check(), OptionsError);
  bad = BundleAdjustmentOptions();
  bad.planar_base.tilt_sigma_deg = 0.0;
  EXPECT_THROW(bad.Check(), OptionsError);
  bad = BundleAdjustmentOptions();
  bad.planar_base.height_sigma_m = -0.01;
  EXPECT_THROW(bad.Check(), OptionsError);
}

// A wheeled robot on a flat floor (the test mount: camera 0.5 m up, pitched
// 20 degrees down) drives 0.6 m while turning 60 degrees, looking at points
// 1.5-4 m ahead. Observations carry 0.3 px of noise, and one in ten is a
// mistrack 3-8 px off, all roughly along `outlier_direction` (features
// that slid along edges the same way). The odometry is planar (2D drift
// composed with the mount), as a dataset with odometry2d.txt gives it.
struct WheeledScene {
  Camera camera = testing::SyntheticCamera();
  Rigid3d base_from_cam = testing::BaseFromCam();
  std::vector<Rigid3d> world_from_cam;  // truth
  std::vector<Rigid3d> odometry;        // world_from_cam, planar
  std::vector<Eigen::Vector3d> points;  // truth of tracks[i]
  std::vector<Track> tracks;
  int num_mistracks = 0;
};

WheeledScene MakeWheeledScene(const Eigen::Vector2d& outlier_direction,
                              uint64_t seed) {
  WheeledScene scene;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  const int n = 60;
  for (int i = 0; i < n; ++i) {
    const Pose2d base{0.01 * i, 0.0005 * i * i, DegToRad(1.0) * i};
    // 2D drift: lateral offset and heading error growing along the run (no
    // scale error: the points then show the shape).
    const Pose2d odometry{base.x, base.y + 0.002 * i / n,
                          base.yaw + DegToRad(0.6) * i / n};
    scene.world_from_cam.push_back(
        WorldFromCamOfBase(base, scene.base_from_cam));
    scene.odometry.push_back(WorldFromCamOfBase(odometry, scene.base_from_cam));
  }
  const Camera& camera = scene.camera;
  for (int t = 0; t < 600; ++t) {
    const int length = 10 + static_cast<int>(uniform(rng) * 31);
    const int start = static_cast<int>(uniform(rng) * (n - length + 1));
    const int mid = start + length / 2;
    // One draw per statement: the order of draws in one expression is the
    // compiler's (util/random.h).
    const double u = uniform(rng);
    const double v = uniform(rng);
    const Eigen::Vector2d px(camera.cx + (u - 0.5) * 500.0,
                             camera.cy + (v - 0.5) * 300.0);
    const Eigen::Vector3d x =
        scene.world_from_cam[mid] *
        (Eigen::Vector3d(camera.NormalizedFromImage(px).homogeneous()) *
         (1.5 + 2.5 * uniform(rng)));
    Track track{static_cast<FeatureId>(scene.points.size()), {}};
    for (int f = start; f < start + length; ++f) {
      const Eigen::Vector3d xc = scene.world_from_cam[f].Inverse() * x;
      if (xc.z() <= 0) continue;
      Eigen::Vector2d obs = camera.ImageFromCam(xc);
      if (!camera.InImage(obs, 2.0)) continue;
      obs += 0.3 * DrawLastFirst<Eigen::Vector2d>(normal, rng);
      if (uniform(rng) < 0.1) {
        const double angle = DegToRad(20.0) * (2.0 * uniform(rng) - 1.0);
        obs += (3.0 + 5.0 * uniform(rng)) *
               (Eigen::Rotation2Dd(angle) * outlier_direction.normalized());
        ++scene.num_mistracks;
      }
      track.observations.push_back({f, obs});
    }
    if (track.observations.size() < 3) continue;
    scene.points.push_back(x);
    scene.tracks.push_back(std::move(track));
  }
  return scene;
}

struct WheeledErrors {
  double median_point_m = 0.0;
  double mean_tilt_deg = 0.0;  // base roll and pitch against the level floor
  double mean_height_m = 0.0;  // base height above the floor
  double mean_rotation_deg = 0.0;
};

WheeledErrors AdjustWheeled(const WheeledScene& scene,
                            const BundleAdjustmentOptions& options,
                            BundleAdjustmentReport* report) {
  std::vector<Rigid3d> poses = scene.odometry;
  std::vector<Landmark> landmarks;
  TriangulationOptions loose;
  loose.max_reprojection_error_px = 6.0;
  loose.max_observation_error_px = 12.0;
  TriangulateTracks(scene.camera, poses, scene.tracks, loose, &landmarks);
  *report =
      BundleAdjust(scene.camera, scene.tracks, options, &poses, &landmarks);
  WheeledErrors e;
  std::vector<double> point_errors;
  for (const Landmark& l : landmarks) {
    point_errors.push_back((l.x_in_world - scene.points[l.id]).norm());
  }
  e.median_point_m = UpperMedian(point_errors);
  const Rigid3d cam_from_base = scene.base_from_cam.Inverse();
  for (size_t i = 0; i < poses.size(); ++i) {
    const Rigid3d world_from_base = poses[i] * cam_from_base;
    const Eigen::Vector3d up =
        world_from_base.rotation * Eigen::Vector3d::UnitZ();
    e.mean_tilt_deg += RadToDeg(std::acos(std::min(1.0, up.z())));
    e.mean_height_m += std::abs(world_from_base.translation.z());
    e.mean_rotation_deg += RadToDeg(
        AngleBetween(poses[i].rotation, scene.world_from_cam[i].rotation));
  }
  e.mean_tilt_deg /= poses.size();
  e.mean_height_m /= poses.size();
  e.mean_rotation_deg /= poses.size();
  return e;
}

TEST(BundleAdjustmentTest, PlanarBasePriorKeepsTheBaseLevel) {
  // Mistracks that lean one way down the image pitch the cameras; the
  // planar-base prior holds the base level (and the points improve with it).
  const WheeledScene scene = MakeWheeledScene(Eigen::Vector2d(0, 1), 22);
  BundleAdjustmentOptions options;
  options.outlier_threshold_px = 0.0;  // the prior alone
  BundleAdjustmentReport free_report, planar_report;
  const WheeledErrors free = AdjustWheeled(scene, options, &free_report);
  options.planar_base.base_from_cam = scene.base_from_cam;
  const WheeledErrors planar = AdjustWheeled(scene, options, &planar_report);
  std::printf(
      "tilt %.4f -> %.4f deg, height %.2f -> %.2f mm, rotation %.4f -> "
      "%.4f deg, points %.2f -> %.2f mm\n",
      free.mean_tilt_deg, planar.mean_tilt_deg, 1e3 * free.mean_height_m,
      1e3 * planar.mean_height_m, free.mean_rotation_deg,
      planar.mean_rotation_deg, 1e3 * free.median_point_m,
      1e3 * planar.median_point_m);
  EXPECT_EQ(free_report.num_planar_priors, 0);
  EXPECT_EQ(planar_report.num_planar_priors, 60);
  // Over scene seeds 21-30 the prior's tilt stays at 0.008-0.015 deg
  // against 0.009-0.030 without (ratio 0.44-0.92), height 0.23-0.83 of it,
  // rotation 0.52-0.94 of it, points 0.84-1.01 of them.
  EXPECT_LT(planar.mean_tilt_deg, 0.02);
  EXPECT_LT(planar.mean_tilt_deg, 0.95 * free.mean_tilt_deg);
  EXPECT_LT(planar.mean_height_m, 0.9 * free.mean_height_m);
  EXPECT_LT(planar.mean_rotation_deg, free.mean_rotation_deg);
  // The points' error here is mostly the odometry's heading drift, which
  // the prior does not touch: not worse.
  EXPECT_LT(planar.median_point_m, 1.05 * free.median_point_m);
  // Switched off, the mount is ignored.
  options.planar_base.enabled = false;
  BundleAdjustmentReport off_report;
  AdjustWheeled(scene, options, &off_report);
  EXPECT_EQ(off_report.num_planar_priors, 0);
}

TEST(BundleAdjustmentTest, OutlierObservationsLeaveTheSecondSolve) {
  // The robust loss still lets mistracks that lean one way pull the poses;
  // taken out after the first solve, they no longer do.
  const WheeledScene scene = MakeWheeledScene(Eigen::Vector2d(1, 0.3), 22);
  BundleAdjustmentOptions options;
  options.outlier_threshold_px = 0.0;
  BundleAdjustmentReport one_report, two_report;
  const WheeledErrors one = AdjustWheeled(scene, options, &one_report);
  options.outlier_threshold_px = BundleAdjustmentOptions().outlier_threshold_px;
  const WheeledErrors two = AdjustWheeled(scene, options, &two_report);
  std::printf(
      "outliers %d (%d mistracks), points out %d; rotation %.4f -> %.4f "
      "deg, points %.2f -> %.2f mm\n",
      two_report.num_outlier_observations, scene.num_mistracks,
      two_report.num_outlier_points, one.mean_rotation_deg,
      two.mean_rotation_deg, 1e3 * one.median_point_m,
      1e3 * two.median_point_m);
  EXPECT_EQ(one_report.num_outlier_observations, 0);
  // Over scene seeds 21-30 it takes out 98-99 % as many observations as
  // there are mistracks; points 0.60-0.86 of the one-solve error. The poses'
  // rotation moves both ways (0.71-1.11): here the mistracks bias the points
  // more than the poses.
  EXPECT_GT(two_report.num_outlier_observations, 0.9 * scene.num_mistracks);
  EXPECT_LT(two_report.num_outlier_observations, 1.1 * scene.num_mistracks);
  EXPECT_LT(two.median_point_m, 0.9 * one.median_point_m);
  EXPECT_LT(two.mean_rotation_deg, 1.2 * one.mean_rotation_deg);
}

// Lens self-calibration on a perturbed lens (k1 x 0.85, the issue's
// perturbation of the radial term): the adjustment finds k1 again, the
// posterior std proves it constrained, and points and poses come out about
// as accurate as with the true lens.
TEST(BundleAdjustmentTest, SelfCalibrationRecoversAPerturbedRadialLens) {
  const testing::TestScene scene = NoisyScene(500, 13);
  Camera wrong = scene.camera;
  wrong.distortion[0] *= 0.85;
  const std::vector<Rigid3d> odometry = testing::SimulateOdometryDrift(
      scene.world_from_cam, testing::OdometryDriftOptions());
  BundleAdjustmentOptions refine;
  refine.intrinsics.enabled = true;
  const LensTrials t = AdjustThreeWays(scene, wrong, odometry, {}, refine);
  const Errors &with_true = t.with_true, &with_wrong = t.with_a,
               &refined = t.with_b;
  const BundleAdjustmentReport& refined_report = t.report_b;
  const IntrinsicsRefinementReport& lens = refined_report.intrinsics;
  std::printf(
      "k1 true %.4f, given %.4f, refined %.4f (std %.5f); points: true lens "
      "%.3f mm, wrong %.3f mm, refined %.3f mm; rotation %.4f / %.4f / %.4f "
      "deg\n%s\n",
      scene.camera.distortion[0], wrong.distortion[0], lens.after.distortion[0],
      lens.posterior_std[kLensK1], 1e3 * with_true.median_point_m,
      1e3 * with_wrong.median_point_m, 1e3 * refined.median_point_m,
      with_true.mean_rotation_deg, with_wrong.mean_rotation_deg,
      refined.mean_rotation_deg, lens.reason.c_str());
  EXPECT_TRUE(lens.attempted);
  EXPECT_TRUE(lens.group_refined[kGroupRadial]);
  EXPECT_FALSE(
      lens.group_refined[kGroupFocal]);  // sideways motion: unconstrained
  EXPECT_EQ(lens.after.fx, wrong.fx);
  EXPECT_EQ(refined_report.camera.distortion, lens.after.distortion);
  EXPECT_NEAR(lens.after.distortion[0], scene.camera.distortion[0], 0.005);
  EXPECT_GT(lens.posterior_std[kLensK1], 0.0);
  EXPECT_LT(lens.posterior_std[kLensK1], 0.5 * lens.prior_std[kLensK1]);
  // One lens over the sequence: its two halves agree on k1.
  EXPECT_TRUE(lens.halves_checked);
  EXPECT_GE(lens.halves_sigmas[kGroupRadial], 0.0);
  EXPECT_LT(lens.halves_sigmas[kGroupRadial],
            refine.intrinsics.max_halves_sigmas);
  // The wrong lens costs a factor ~10 in points and ~25 in rotation; the
  // refined one comes back to within ~30% of the true lens (2.7 vs 3.5 mm,
  // 0.032 vs 0.053 deg): not the 10% on this small scene.
  EXPECT_GT(with_wrong.median_point_m, 5.0 * with_true.median_point_m);
  EXPECT_LT(refined.median_point_m, 1.4 * with_true.median_point_m);
  EXPECT_LT(refined.mean_rotation_deg, 1.9 * with_true.mean_rotation_deg);
  EXPECT_LT(refined.mean_rotation_deg, 0.1 * with_wrong.mean_rotation_deg);
}

// A lens with a third radial term (k3 = -0.02: 2 px at the image corner)
// given with k3 = 0, as a board calibration with k1, k2 only would give it:
// with refine_k3 the adjustment finds k3 (trusted only together with k1,
// k2) and both halves of the frames agree on it.
TEST(BundleAdjustmentTest, SelfCalibrationFindsAThirdRadialTerm) {
  testing::TestSceneOptions scene_options;
  scene_options.points.num_tracks = 2000;
  scene_options.points.pixel_noise_px = 0.3;
  scene_options.seed = 13;
  Camera rim = testing::SyntheticCamera();
  rim.distortion[4] = -0.02;
  scene_options.camera = rim;
  const testing::TestScene scene = testing::MakeTestScene(scene_options);
  Camera given = rim;
  given.distortion[4] = 0.0;
  const std::vector<Rigid3d> odometry = testing::SimulateOdometryDrift(
      scene.world_from_cam, testing::OdometryDriftOptions());
  BundleAdjustmentOptions two_terms, three_terms;
  two_terms.intrinsics.enabled = three_terms.intrinsics.enabled = true;
  three_terms.intrinsics.refine_k3 = true;
  const LensTrials t =
      AdjustThreeWays(scene, given, odometry, two_terms, three_terms);
  const Errors &with_true = t.with_true, &with_two = t.with_a,
               &with_three = t.with_b;
  const BundleAdjustmentReport& two_report = t.report_a;
  const IntrinsicsRefinementReport& lens = t.report_b.intrinsics;
  std::printf(
      "k3 true %.4f, refined %.4f (std %.5f, halves %.1f sigmas); points: "
      "true lens %.3f mm, two terms %.3f mm, three %.3f mm; rotation %.4f / "
      "%.4f / %.4f deg\n%s\n",
      rim.distortion[4], lens.after.distortion[4], lens.posterior_std[kLensK3],
      lens.halves_sigmas[kGroupK3], 1e3 * with_true.median_point_m,
      1e3 * with_two.median_point_m, 1e3 * with_three.median_point_m,
      with_true.mean_rotation_deg, with_two.mean_rotation_deg,
      with_three.mean_rotation_deg, lens.reason.c_str());
  EXPECT_FALSE(two_report.intrinsics.group_refined[kGroupK3]);
  EXPECT_EQ(two_report.camera.distortion[4], 0.0);
  EXPECT_TRUE(lens.group_refined[kGroupRadial]);
  EXPECT_TRUE(lens.group_refined[kGroupK3]);
  EXPECT_NEAR(lens.after.distortion[4], rim.distortion[4], 0.005);
  EXPECT_LT(lens.halves_sigmas[kGroupK3],
            three_terms.intrinsics.max_halves_sigmas);
  // On this scene the map does not come back to the true lens' (1.99 vs
  // 1.46 mm; the two-term fit 1.94 mm): k3 is found, the map is not
  // harmed. The real desk's gain is in docs/benchmarks.md.
  EXPECT_LT(with_three.median_point_m, 1.5 * with_true.median_point_m);
}

// k3 refined alone would take up the error of k1, k2: it is trusted only
// with them.
TEST(BundleAdjustmentTest, SelfCalibrationTrustsK3OnlyWithK1K2) {
  IntrinsicsRefinementOptions options;
  options.enabled = options.refine_k3 = true;
  options.check_halves = false;
  IntrinsicsRefinementReport report;
  report.before = testing::SyntheticCamera();
  report.prior_std = LensPriorSigmas(report.before, options);
  report.candidate = LensParameters(report.before);
  report.posterior_std = report.prior_std;
  // k1, k2 left loose by the data, k3 tight.
  report.posterior_std[kLensK3] = 0.1 * report.prior_std[kLensK3];
  JudgeLensGroups(options, /*posterior_ok=*/true, &report);
  EXPECT_FALSE(report.group_refined[kGroupRadial]);
  EXPECT_FALSE(report.group_refined[kGroupK3]);
  EXPECT_NE(report.reason.find("k3 kept: k1, k2 are"), std::string::npos)
      << report.reason;
  report.posterior_std[kLensK1] = 0.1 * report.prior_std[kLensK1];
  report.posterior_std[kLensK2] = 0.1 * report.prior_std[kLensK2];
  JudgeLensGroups(options, /*posterior_ok=*/true, &report);
  EXPECT_TRUE(report.group_refined[kGroupRadial]);
  EXPECT_TRUE(report.group_refined[kGroupK3]);
}

// A lens that is not the same over the sequence (here k1 30 % weaker from
// the middle frame on, as a model error would look): the whole sequence
// still gives k1 a small marginal std, but the trials on each half disagree
// by many of their sigmas, so the check keeps the given lens and says why.
TEST(BundleAdjustmentTest, SelfCalibrationKeepsAGroupItsHalvesDisagreeOn) {
  const testing::TestScene scene = NoisyScene(500, 13);
  Camera second_lens = scene.camera;
  second_lens.distortion[0] *= 0.7;
  const int middle = static_cast<int>(scene.world_from_cam.size()) / 2;
  std::vector<Track> tracks = scene.tracks;
  for (Track& t : tracks) {
    for (Observation& o : t.observations) {
      if (o.frame < middle) continue;
      o.px = second_lens.ImageFromCam(
          scene.camera.NormalizedFromImage(o.px).homogeneous());
    }
  }
  BundleAdjustmentOptions refine;
  refine.intrinsics.enabled = true;
  BundleAdjustmentReport checked, unchecked;
  AdjustWithLens(scene, scene.camera, tracks, scene.world_from_cam, refine,
                 &checked);
  refine.intrinsics.check_halves = false;
  AdjustWithLens(scene, scene.camera, tracks, scene.world_from_cam, refine,
                 &unchecked);
  const IntrinsicsRefinementReport& lens = checked.intrinsics;
  std::printf(
      "k1 halves %.4f / %.4f (std %.5f / %.5f), %.1f sigmas apart\n%s\n",
      lens.halves_candidate[0][kLensK1], lens.halves_candidate[1][kLensK1],
      lens.halves_std[0][kLensK1], lens.halves_std[1][kLensK1],
      lens.halves_sigmas[kGroupRadial], lens.reason.c_str());
  // Without the check the std test alone trusts the compromise.
  EXPECT_TRUE(unchecked.intrinsics.group_refined[kGroupRadial]);
  EXPECT_FALSE(unchecked.intrinsics.halves_checked);
  // With it, each half finds its own k1 and the lens is kept.
  ASSERT_TRUE(lens.halves_checked);
  EXPECT_NEAR(lens.halves_candidate[0][kLensK1], scene.camera.distortion[0],
              0.01);
  EXPECT_NEAR(lens.halves_candidate[1][kLensK1], second_lens.distortion[0],
              0.01);
  EXPECT_GT(lens.halves_sigmas[kGroupRadial],
            refine.intrinsics.max_halves_sigmas);
  EXPECT_FALSE(lens.group_refined[kGroupRadial]);
  EXPECT_NE(lens.reason.find("radial distortion kept: the two halves of the "
                             "frames disagree"),
            std::string::npos);
  EXPECT_EQ(checked.camera.distortion, scene.camera.distortion);
}

// The trial kept `group` because the data did not shrink the std of its
// parameter `index` enough, and the report says so.
void ExpectKeptUnconstrained(const IntrinsicsRefinementReport& lens,
                             const IntrinsicsRefinementOptions& options,
                             LensGroup group, LensIndex index,
                             const std::string& name) {
  EXPECT_TRUE(lens.attempted);
  EXPECT_FALSE(lens.group_refined[group]);
  EXPECT_NE(lens.reason.find(name + " kept: not constrained"),
            std::string::npos);
  EXPECT_GT(lens.posterior_std[index],
            options.max_posterior_to_prior_std * lens.prior_std[index]);
}

// Data that do not constrain a group: a camera translating sideways with
// known (odometry) motion cannot tell its focal length from the depth of
// the points (f and depth scale together); with 60 points the lens
// distortion and the depth spread barely tell them apart. Asked to refine the
// focal length, the trial finds its posterior std near the prior's and keeps
// the given value, and the report says why.
TEST(BundleAdjustmentTest, SelfCalibrationKeepsAnUnconstrainedFocalLength) {
  const testing::TestScene scene = NoisyScene(60, 5);
  Camera given = scene.camera;
  given.fx *= 1.01;
  given.fy *= 1.01;
  BundleAdjustmentOptions refine;
  refine.intrinsics.enabled = true;
  refine.intrinsics.refine_focal = true;
  BundleAdjustmentReport report;
  AdjustWithLens(scene, given, scene.tracks, scene.world_from_cam, refine,
                 &report);
  const IntrinsicsRefinementReport& lens = report.intrinsics;
  std::printf("fx std %.2f px (prior %.2f)\n%s\n", lens.posterior_std[kLensFx],
              lens.prior_std[kLensFx], lens.reason.c_str());
  ExpectKeptUnconstrained(lens, refine.intrinsics, kGroupFocal, kLensFx,
                          "focal length");
  EXPECT_EQ(lens.after.fx, given.fx);
  EXPECT_EQ(report.camera.fx, given.fx);
}

// Only the image centre seen (observations within 30 px of the principal
// point, where k1 moves a point by < 0.02 px): the data cannot constrain
// the radial distortion, so the default trial keeps the given (wrong) k1,
// and the report says why.
TEST(BundleAdjustmentTest, SelfCalibrationKeepsTheLensWhenOnlyTheCentreIsSeen) {
  testing::TestSceneOptions options;
  options.points.num_tracks = 3000;
  options.points.pixel_noise_px = 0.3;
  options.seed = 7;
  const testing::TestScene scene = testing::MakeTestScene(options);
  const Eigen::Vector2d centre(scene.camera.cx, scene.camera.cy);
  std::vector<Track> central;
  for (const Track& t : scene.tracks) {
    Track kept{t.id, {}};
    for (const Observation& o : t.observations) {
      if ((o.px - centre).norm() <= 30.0) kept.observations.push_back(o);
    }
    if (kept.observations.size() >= 3) central.push_back(std::move(kept));
  }
  ASSERT_GT(central.size(), 30u);
  Camera given = scene.camera;
  given.distortion[0] *= 0.85;
  BundleAdjustmentOptions refine;
  refine.intrinsics.enabled = true;
  BundleAdjustmentReport report;
  AdjustWithLens(scene, given, central, scene.world_from_cam, refine, &report);
  const IntrinsicsRefinementReport& lens = report.intrinsics;
  std::printf("%zu central tracks; k1 std %.4f (prior %.4f)\n%s\n",
              central.size(), lens.posterior_std[kLensK1],
              lens.prior_std[kLensK1], lens.reason.c_str());
  ExpectKeptUnconstrained(lens, refine.intrinsics, kGroupRadial, kLensK1,
                          "radial distortion");
  EXPECT_FALSE(lens.refined());
  EXPECT_EQ(report.camera.distortion, given.distortion);
  EXPECT_EQ(lens.after.distortion, given.distortion);
}

// Self-calibration of a fisheye (equidistant) lens: the lens block's k1, k2
// are the equidistant k1, k2 (k3, k4 kept); a wrong k1 is found again.
TEST(BundleAdjustmentTest, SelfCalibrationRecoversAFisheyeK1) {
  const testing::TestScene scene = FisheyeScene();
  const Camera& fisheye = scene.camera;
  const std::vector<Rigid3d> odometry = testing::SimulateOdometryDrift(
      scene.world_from_cam, testing::OdometryDriftOptions());
  Camera wrong = fisheye;
  wrong.distortion[0] += 0.03;
  BundleAdjustmentOptions refine;
  refine.intrinsics.enabled = true;
  BundleAdjustmentReport true_report, refined_report;
  const Errors with_true =
      AdjustWithLens(scene, fisheye, scene.tracks, odometry, {}, &true_report);
  const Errors refined = AdjustWithLens(scene, wrong, scene.tracks, odometry,
                                        refine, &refined_report);
  const IntrinsicsRefinementReport& lens = refined_report.intrinsics;
  std::printf(
      "fisheye k1 true %.4f, given %.4f, refined %.4f (std %.5f); points "
      "%.3f / %.3f mm, rotation %.4f / %.4f deg\n%s\n",
      fisheye.distortion[0], wrong.distortion[0], lens.after.distortion[0],
      lens.posterior_std[kLensK1], 1e3 * with_true.median_point_m,
      1e3 * refined.median_point_m, with_true.mean_rotation_deg,
      refined.mean_rotation_deg, lens.reason.c_str());
  EXPECT_TRUE(lens.group_refined[kGroupRadial]);
  EXPECT_EQ(lens.after.model, LensModel::kEquidistant);
  EXPECT_NEAR(lens.after.distortion[0], fisheye.distortion[0], 0.01);
  EXPECT_EQ(lens.after.distortion[2], wrong.distortion[2]);
  EXPECT_EQ(lens.after.distortion[3], wrong.distortion[3]);
  EXPECT_LT(refined_report.final_rms_error_px, 0.5);
  EXPECT_LT(refined.median_point_m, 1.5 * with_true.median_point_m);
}

TEST(BundleAdjustmentTest, SelfCalibrationOptionsChecked) {
  BundleAdjustmentOptions options;
  options.intrinsics.enabled = true;
  options.refine_distortion = true;
  EXPECT_THROW(options.Check(), OptionsError);
  options.refine_distortion = false;
  options.intrinsics.k1_sigma = 0.0;
  EXPECT_THROW(options.Check(), OptionsError);
  options.intrinsics.k1_sigma = 0.05;
  options.intrinsics.refine_radial = false;
  options.intrinsics.refine_focal = false;
  EXPECT_THROW(options.Check(), OptionsError);
  options.intrinsics.refine_focal = true;
  EXPECT_NO_THROW(options.Check());
  options.intrinsics.max_halves_sigmas = 0.0;
  EXPECT_THROW(options.Check(), OptionsError);
}

}  // namespace
}  // namespace monomap
