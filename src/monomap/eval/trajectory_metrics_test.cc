#include "monomap/eval/trajectory_metrics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "monomap/util/angles.h"
#include "monomap/util/error.h"
#include "monomap/util/random.h"

namespace monomap {
namespace {

// A non-planar loop with turning cameras, 10 Hz.
std::vector<TimedPose> GroundTruth(int n = 200) {
  std::vector<TimedPose> poses;
  for (int i = 0; i < n; ++i) {
    const double a = 0.05 * i;
    TimedPose p;
    p.timestamp = 100.0 + 0.1 * i;
    p.world_from_cam = Rigid3d(
        YawRotation(a) * Eigen::Quaterniond(Eigen::AngleAxisd(
                             0.2 * std::sin(a), Eigen::Vector3d::UnitX())),
        Eigen::Vector3d(3.0 * std::cos(a), 2.0 * std::sin(a),
                        0.5 * std::sin(2 * a)));
    poses.push_back(p);
  }
  return poses;
}

const Rigid3d kWorldChange(Eigen::Quaterniond(Eigen::AngleAxisd(
                               DegToRad(30),
                               Eigen::Vector3d(1, 2, 3).normalized())),
                           Eigen::Vector3d(2.0, -1.0, 0.5));

// est = scale * kWorldChange applied to gt, plus noise on positions (sigma
// per axis, metres in the estimate frame) and rotations (sigma radians).
std::vector<TimedPose> Transformed(const std::vector<TimedPose>& gt,
                                   double scale, double sigma_t, double sigma_r,
                                   unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<TimedPose> est = gt;
  for (auto& p : est) {
    Rigid3d& w = p.world_from_cam;
    w.translation = scale * (kWorldChange.rotation * w.translation) +
                    kWorldChange.translation +
                    sigma_t * DrawLastFirst<Eigen::Vector3d>(g, rng);
    w.rotation = (kWorldChange.rotation * w.rotation *
                  QuaternionFromRotationVector(
                      sigma_r * DrawLastFirst<Eigen::Vector3d>(g, rng)))
                     .normalized();
  }
  return est;
}

TEST(AssociationTest, MatchesWithinMaxDt) {
  const auto gt = GroundTruth(50);
  auto est = gt;
  for (size_t i = 0; i < est.size(); ++i) {
    est[i].timestamp += (i % 5 == 0) ? 5e-3 : 4e-4;  // every 5th too far
  }
  const auto pairs = AssociateByTimestamp(est, gt, 1e-3);
  EXPECT_EQ(pairs.size(), 40u);
  for (const auto& [i, j] : pairs) EXPECT_EQ(i, j);
  est.erase(est.begin() + 10, est.end());
  EXPECT_EQ(AssociateByTimestamp(est, gt, 1e-3).size(), 8u);
  std::swap(est[2], est[3]);
  EXPECT_THROW(AssociateByTimestamp(est, gt, 1e-3), StageError);
}

TEST(AbsoluteTrajectoryErrorTest, SE3RecoversRigidTransform) {
  const auto gt = GroundTruth();
  const auto est = Transformed(gt, 1.0, 1e-3, DegToRad(0.1), 7);

  const TrajectoryErrors none =
      AbsoluteTrajectoryError(est, gt, Alignment::kNone, 1e-3);
  EXPECT_EQ(none.matched, 200u);
  EXPECT_GT(none.translation_m.rms, 1.0);
  EXPECT_NEAR(none.rotation_deg.median, 30.0, 0.5);

  const TrajectoryErrors se3 =
      AbsoluteTrajectoryError(est, gt, Alignment::kSE3, 1e-3);
  EXPECT_EQ(se3.matched, 200u);
  // 1 mm noise per axis: |error| has rms sqrt(3) mm.
  EXPECT_LT(se3.translation_m.rms, 2.0e-3);
  EXPECT_GT(se3.translation_m.rms, 1.4e-3);
  EXPECT_LT(se3.translation_m.max, 6e-3);
  // 0.1 deg per axis: rotation angle rms ~ 0.17 deg.
  EXPECT_LT(se3.rotation_deg.rms, 0.2);
  EXPECT_DOUBLE_EQ(se3.scale, 1.0);

  const Sim3d align = AlignTrajectories(est, gt, Alignment::kSE3, 1e-3);
  const Rigid3d expected = kWorldChange.Inverse();
  EXPECT_LT(RadToDeg(AngleBetween(align.rigid.rotation, expected.rotation)),
            0.02);
  EXPECT_LT((align.rigid.translation - expected.translation).norm(), 1e-3);
}

TEST(AbsoluteTrajectoryErrorTest, Sim3RecoversScale) {
  const auto gt = GroundTruth();
  // Estimate at half scale; 0.5 mm noise there is 1 mm in gt units.
  const auto est = Transformed(gt, 0.5, 0.5e-3, DegToRad(0.1), 8);

  const TrajectoryErrors se3 =
      AbsoluteTrajectoryError(est, gt, Alignment::kSE3, 1e-3);
  EXPECT_GT(se3.translation_m.rms, 0.5);  // scale error left over

  const TrajectoryErrors sim3 =
      AbsoluteTrajectoryError(est, gt, Alignment::kSim3, 1e-3);
  EXPECT_NEAR(sim3.scale, 2.0, 2e-3);
  EXPECT_LT(sim3.translation_m.rms, 2.0e-3);
  EXPECT_GT(sim3.translation_m.rms, 1.4e-3);
  EXPECT_LT(sim3.rotation_deg.rms, 0.2);
}

TEST(AbsoluteTrajectoryErrorTest, Sim3PosesRecoversScaleAlsoOnALine) {
  const auto gt = GroundTruth();
  const auto est = Transformed(gt, 0.5, 0.5e-3, DegToRad(0.1), 8);
  const TrajectoryErrors sim3 =
      AbsoluteTrajectoryError(est, gt, Alignment::kSim3Poses, 1e-3);
  EXPECT_NEAR(sim3.scale, 2.0, 2e-3);
  EXPECT_LT(sim3.translation_m.rms, 3.0e-3);
  EXPECT_LT(sim3.rotation_deg.rms, 0.2);
  // A straight drive, 2 % short, in a frame turned by 20 deg about z and
  // 3 deg about x: the orientations fix the roll about the line that the
  // positions leave free.
  const Rigid3d gt_from_est(
      Eigen::Quaterniond(
          Eigen::AngleAxisd(DegToRad(20), Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(DegToRad(3), Eigen::Vector3d::UnitX())),
      Eigen::Vector3d(1, -2, 0.3));
  std::vector<TimedPose> line_gt(20), line_est(20);
  for (int i = 0; i < 20; ++i) {
    line_gt[i].timestamp = line_est[i].timestamp = i;
    line_gt[i].world_from_cam.translation = Eigen::Vector3d(0.1 * i, 0, 0.4);
    line_est[i].world_from_cam =
        gt_from_est.Inverse() * line_gt[i].world_from_cam;
    line_est[i].world_from_cam.translation /= 1.02;
  }
  const Sim3d align =
      AlignTrajectories(line_est, line_gt, Alignment::kSim3Poses);
  EXPECT_NEAR(align.scale, 1.02, 1e-9);
  EXPECT_LT(RadToDeg(AngleBetween(align.rigid.rotation, gt_from_est.rotation)),
            1e-6);
  EXPECT_THROW(AlignTrajectories(line_est, line_gt, Alignment::kSim3),
               StageError);
  EXPECT_EQ(ParseAlignment("sim3-poses"), Alignment::kSim3Poses);
}

TEST(AbsoluteTrajectoryErrorTest, Se3PosesRemovesOneRigidOffsetOnly) {
  // A straight drive in a frame turned by 0.05 deg about the line (which
  // positions alone leave free) and shifted, 1 % long, 0.02 deg of noise.
  const Rigid3d gt_from_est(Eigen::Quaterniond(Eigen::AngleAxisd(
                                DegToRad(0.05), Eigen::Vector3d::UnitX())),
                            Eigen::Vector3d(0.01, -0.02, 0.003));
  std::mt19937 rng(4);
  std::normal_distribution<double> noise(0.0, DegToRad(0.02));
  std::vector<TimedPose> gt(40), est(40);
  for (int i = 0; i < 40; ++i) {
    gt[i].timestamp = est[i].timestamp = i;
    gt[i].world_from_cam.translation = Eigen::Vector3d(0.05 * i, 0, 0.4);
    est[i].world_from_cam = gt_from_est.Inverse() * gt[i].world_from_cam;
    est[i].world_from_cam.rotation =
        est[i].world_from_cam.rotation *
        Eigen::Quaterniond(Eigen::AngleAxisd(
            noise(rng), Eigen::Vector3d(0.3, 0.5, 0.8).normalized()));
    est[i].world_from_cam.translation *= 1.01;
  }
  const Sim3d align = AlignTrajectories(est, gt, Alignment::kSE3Poses);
  EXPECT_EQ(align.scale, 1.0);
  // The offset's rotation comes back to within the noise's mean (0.02 deg
  // / sqrt(40)) ...
  EXPECT_LT(RadToDeg(AngleBetween(align.rigid.rotation, gt_from_est.rotation)),
            0.01);
  // ... the orientations' own noise is left, not the offset ...
  const TrajectoryErrors rigid =
      AbsoluteTrajectoryError(est, gt, Alignment::kSE3Poses);
  const TrajectoryErrors none =
      AbsoluteTrajectoryError(est, gt, Alignment::kNone);
  EXPECT_GT(none.rotation_deg.mean, 0.045);
  EXPECT_LT(rigid.rotation_deg.mean, 0.035);
  // ... and the 1 % scale error stays (1 % of up to 1 m from the middle),
  // which sim3-poses removes down to the rotation's residual error.
  EXPECT_GT(rigid.translation_m.max, 0.008);
  EXPECT_LT(
      AbsoluteTrajectoryError(est, gt, Alignment::kSim3Poses).translation_m.max,
      5e-4);
  EXPECT_EQ(ParseAlignment("se3-poses"), Alignment::kSE3Poses);
}

TEST(AbsoluteTrajectoryErrorTest, FirstPoseExactForGlobalTransform) {
  const auto gt = GroundTruth();
  const auto est = Transformed(gt, 1.0, 0.0, 0.0, 9);
  const TrajectoryErrors first =
      AbsoluteTrajectoryError(est, gt, Alignment::kFirstPose, 1e-3);
  EXPECT_EQ(first.matched, 200u);
  EXPECT_LT(first.translation_m.max, 1e-12);
  EXPECT_LT(first.rotation_deg.max, 1e-5);
  // With noise on the first pose only, its error spreads along the path:
  // a 1 deg yaw error at the first pose moves poses 5 m away by ~9 cm.
  auto perturbed = est;
  perturbed[0].world_from_cam =
      perturbed[0].world_from_cam *
      Rigid3d(YawRotation(DegToRad(1)), Eigen::Vector3d::Zero());
  const TrajectoryErrors off =
      AbsoluteTrajectoryError(perturbed, gt, Alignment::kFirstPose, 1e-3);
  EXPECT_GT(off.translation_m.max, 0.05);
  EXPECT_NEAR(off.rotation_deg.median, 1.0, 1e-6);
}

TEST(AbsoluteTrajectoryErrorTest, TooFewMatchesOrDegenerate) {
  const auto gt = GroundTruth(10);
  std::vector<TimedPose> est(gt.begin(), gt.begin() + 2);
  EXPECT_NO_THROW(AbsoluteTrajectoryError(est, gt, Alignment::kFirstPose));
  EXPECT_THROW(AbsoluteTrajectoryError(est, gt, Alignment::kSE3), StageError);
  EXPECT_THROW(AbsoluteTrajectoryError(est, gt, Alignment::kSim3), StageError);
  est.resize(1);
  EXPECT_THROW(AbsoluteTrajectoryError(est, gt, Alignment::kNone), StageError);
  // Collinear positions: rotation about the line is undetermined.
  std::vector<TimedPose> line(5);
  for (int i = 0; i < 5; ++i) {
    line[i].timestamp = i;
    line[i].world_from_cam.translation = Eigen::Vector3d(i, 0, 0);
  }
  EXPECT_THROW(AbsoluteTrajectoryError(line, line, Alignment::kSE3),
               StageError);
  EXPECT_EQ(AbsoluteTrajectoryError(line, line, Alignment::kFirstPose)
                .translation_m.max,
            0.0);
}

TEST(RelativePoseErrorTest, ConstantPerStepBiasEqualsBias) {
  const auto gt = GroundTruth();
  const Rigid3d bias(QuaternionFromRotationVector(DegToRad(0.5) *
                                                  Eigen::Vector3d(0, 0.6, 0.8)),
                     Eigen::Vector3d(0.01, 0.0, 0.002));
  std::vector<TimedPose> est = gt;
  for (size_t i = 1; i < gt.size(); ++i) {
    const Rigid3d step =
        gt[i - 1].world_from_cam.Inverse() * gt[i].world_from_cam;
    est[i].world_from_cam = est[i - 1].world_from_cam * step * bias;
  }
  const TrajectoryErrors rpe = RelativePoseError(est, gt, 1, 1e-3);
  EXPECT_EQ(rpe.matched, 199u);
  const double bias_t = bias.translation.norm();
  // Every step's error is exactly the bias.
  EXPECT_NEAR(rpe.translation_m.mean, bias_t, 1e-9);
  EXPECT_NEAR(rpe.translation_m.max, bias_t, 1e-9);
  EXPECT_NEAR(rpe.translation_m.median, bias_t, 1e-9);
  EXPECT_NEAR(rpe.rotation_deg.mean, 0.5, 1e-6);
  EXPECT_NEAR(rpe.rotation_deg.max, 0.5, 1e-6);
  // Over 2 frames the error is bias composed with itself through the step.
  const TrajectoryErrors rpe2 = RelativePoseError(est, gt, 2, 1e-3);
  EXPECT_EQ(rpe2.matched, 198u);
  EXPECT_GT(rpe2.translation_m.mean, 1.5 * bias_t);
  EXPECT_NEAR(rpe2.rotation_deg.median, 1.0, 0.05);
  // The ATE of the same drifting trajectory grows far beyond one bias.
  EXPECT_GT(
      AbsoluteTrajectoryError(est, gt, Alignment::kFirstPose).translation_m.max,
      0.5);
}

TEST(RelativePoseErrorTest, InvariantToGlobalTransformAndChecksArgs) {
  const auto gt = GroundTruth(30);
  const auto est = Transformed(gt, 1.0, 0.0, 0.0, 3);
  const TrajectoryErrors rpe = RelativePoseError(est, gt, 5);
  EXPECT_EQ(rpe.matched, 25u);
  EXPECT_LT(rpe.translation_m.max, 1e-12);
  EXPECT_LT(rpe.rotation_deg.max, 1e-5);
  EXPECT_THROW(RelativePoseError(est, gt, 0), OptionsError);
  EXPECT_THROW(RelativePoseError(est, gt, 30), StageError);
  EXPECT_NO_THROW(RelativePoseError(est, gt, 29));
}

TEST(ParseAlignmentTest, NamesAndErrors) {
  EXPECT_EQ(ParseAlignment("none"), Alignment::kNone);
  EXPECT_EQ(ParseAlignment("first"), Alignment::kFirstPose);
  EXPECT_EQ(ParseAlignment("se3"), Alignment::kSE3);
  EXPECT_EQ(ParseAlignment("sim3"), Alignment::kSim3);
  EXPECT_THROW(ParseAlignment("SE3"), OptionsError);
}

}  // namespace
}  // namespace monomap
