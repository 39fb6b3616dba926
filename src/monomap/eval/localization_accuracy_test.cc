#include "monomap/eval/localization_accuracy.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "monomap/util/angles.h"
#include "monomap/util/error.h"

namespace monomap {
namespace {

// A robot driving along x at 30 Hz, camera 0.5 m above the floor.
std::vector<TimedPose> GroundTruth(int n) {
  std::vector<TimedPose> poses;
  for (int i = 0; i < n; ++i) {
    poses.push_back({1000.0 + i / 30.0,
                     Rigid3d(YawRotation(0.01 * i),
                             Eigen::Vector3d(0.013 * i, 0.0, 0.5))});
  }
  return poses;
}

// The ground truth moved by `offset_m(i)` along y and turned by
// `yaw_deg(i)` at step i.
std::vector<TimedPose> Perturbed(const std::vector<TimedPose>& gt,
                                 const std::function<double(int)>& offset_m,
                                 const std::function<double(int)>& yaw_deg) {
  std::vector<TimedPose> est = gt;
  for (int i = 0; i < static_cast<int>(est.size()); ++i) {
    est[i].world_from_cam.translation.y() += offset_m(i);
    est[i].world_from_cam.rotation =
        YawRotation(DegToRad(yaw_deg(i))) * est[i].world_from_cam.rotation;
  }
  return est;
}

TEST(LocalizationAccuracyTest, ConvergesAtAKnownStep) {
  const auto gt = GroundTruth(100);
  // Lost (2 m, 90 deg off) for 30 steps, then 3 cm / 1 deg off.
  const auto est = Perturbed(
      gt, [](int i) { return i < 30 ? 2.0 : 0.03; },
      [](int i) { return i < 30 ? 90.0 : 1.0; });
  const LocalizationAccuracy a = EvaluateLocalization(est, gt);
  EXPECT_EQ(a.matched, 100);
  ASSERT_EQ(a.translation_error_m.size(), 100u);
  EXPECT_NEAR(a.translation_error_m[0], 2.0, 1e-9);
  EXPECT_NEAR(a.rotation_error_deg[0], 90.0, 1e-6);
  EXPECT_TRUE(a.success);
  EXPECT_EQ(a.converged_step, 30);
  EXPECT_EQ(a.first_within_step, 30);
  EXPECT_NEAR(a.fraction_within, 0.7, 1e-12);
  EXPECT_NEAR(a.final_translation_error_m, 0.03, 1e-9);
  EXPECT_NEAR(a.final_rotation_error_deg, 1.0, 1e-6);
  EXPECT_NEAR(a.mean_translation_error_m, 0.03, 1e-9);
  EXPECT_NEAR(a.mean_rotation_error_deg, 1.0, 1e-6);
  EXPECT_NEAR(a.mean_translation_error_all_m, 0.3 * 2.0 + 0.7 * 0.03, 1e-9);
  const nlohmann::json j = a.ToJson();
  EXPECT_EQ(j["converged_step"], 30);
  EXPECT_EQ(j["translation_error_m"].size(), 100u);
  EXPECT_FALSE(a.ToJson(false).contains("translation_error_m"));
}

TEST(LocalizationAccuracyTest, RemovesOneRigidOffsetOfTheMapFrame) {
  const auto gt = GroundTruth(90);
  // Lost for 20 steps, then exact in a frame turned by 0.3 deg (about a
  // tilted axis) and shifted by 2 cm: a map frame off the truth's.
  const Rigid3d est_from_gt(
      Eigen::Quaterniond(Eigen::AngleAxisd(
          DegToRad(0.3), Eigen::Vector3d(0.2, 1.0, 0.4).normalized())),
      Eigen::Vector3d(0.02, 0.0, 0.0));
  std::vector<TimedPose> est = gt;
  for (int i = 0; i < 90; ++i) {
    est[i].world_from_cam = est_from_gt * gt[i].world_from_cam;
    if (i < 20) est[i].world_from_cam.translation.y() += 3.0;
  }
  const LocalizationAccuracy a = EvaluateLocalization(est, gt);
  EXPECT_EQ(a.converged_step, 20);
  EXPECT_NEAR(a.mean_rotation_error_deg, 0.3, 1e-6);
  EXPECT_GT(a.mean_translation_error_m, 0.015);
  EXPECT_LT(a.mean_rotation_error_rigid_deg, 1e-6);
  EXPECT_LT(a.mean_translation_error_rigid_m, 1e-9);
  EXPECT_NEAR(a.ToJson(false)["mean_rotation_error_rigid_deg"].get<double>(),
              a.mean_rotation_error_rigid_deg, 1e-12);
}

TEST(LocalizationAccuracyTest, BothThresholdsMustHold) {
  const auto gt = GroundTruth(50);
  // Position right from step 10 but heading 8 deg off until step 20.
  const auto est = Perturbed(
      gt, [](int i) { return i < 10 ? 1.0 : 0.02; },
      [](int i) { return i < 20 ? 8.0 : 0.5; });
  LocalizationAccuracy a = EvaluateLocalization(est, gt);
  EXPECT_EQ(a.converged_step, 20);
  // Looser thresholds: converged once the position is right.
  LocalizationAccuracyOptions loose;
  loose.max_rotation_error_deg = 10.0;
  a = EvaluateLocalization(est, gt, loose);
  EXPECT_EQ(a.converged_step, 10);
}

TEST(LocalizationAccuracyTest, NeverConverges) {
  const auto gt = GroundTruth(60);
  // A wrong mode: 1.5 m away the whole run, right heading.
  const auto est = Perturbed(
      gt, [](int) { return 1.5; }, [](int) { return 0.0; });
  const LocalizationAccuracy a = EvaluateLocalization(est, gt);
  EXPECT_FALSE(a.success);
  EXPECT_EQ(a.converged_step, -1);
  EXPECT_EQ(a.first_within_step, -1);
  EXPECT_EQ(a.fraction_within, 0.0);
  EXPECT_NEAR(a.final_translation_error_m, 1.5, 1e-9);
  EXPECT_TRUE(std::isnan(a.mean_translation_error_m));
  EXPECT_TRUE(std::isnan(a.mean_rotation_error_deg));
  EXPECT_TRUE(std::isnan(a.mean_rotation_error_rigid_deg));
  EXPECT_NEAR(a.mean_translation_error_all_m, 1.5, 1e-9);
  const nlohmann::json j = a.ToJson(false);
  EXPECT_TRUE(j["mean_translation_error_m"].is_null());
  EXPECT_EQ(j["converged_step"], -1);
}

TEST(LocalizationAccuracyTest, ConvergesThenDiverges) {
  const auto gt = GroundTruth(80);
  // Found at step 15, lost again from step 50 (drifting away 1 cm/step).
  const auto est = Perturbed(
      gt,
      [](int i) {
        return i < 15 ? 3.0 : i < 50 ? 0.045 : 0.045 + 0.01 * (i - 49);
      },
      [](int) { return 2.0; });
  const LocalizationAccuracy a = EvaluateLocalization(est, gt);
  EXPECT_FALSE(a.success);
  EXPECT_EQ(a.converged_step, -1);
  EXPECT_EQ(a.first_within_step, 15);
  // Within: steps 15..54 (0.095 m at step 54, 0.105 m at step 55).
  EXPECT_NEAR(a.fraction_within, (55 - 15) / 80.0, 1e-12);
  EXPECT_NEAR(a.final_translation_error_m, 0.045 + 0.01 * 30, 1e-9);
  // Converging again for good at the end resets converged_step.
  auto est2 = est;
  for (int i = 70; i < 80; ++i) est2[i] = gt[i];
  const LocalizationAccuracy b = EvaluateLocalization(est2, gt);
  EXPECT_TRUE(b.success);
  EXPECT_EQ(b.converged_step, 70);
  EXPECT_NEAR(b.mean_translation_error_m, 0.0, 1e-12);
}

TEST(LocalizationAccuracyTest, AssociatesByTimestamp) {
  const auto gt = GroundTruth(40);
  // The estimate starts 5 steps late and skips every other frame.
  std::vector<TimedPose> est;
  for (int i = 5; i < 40; i += 2) est.push_back(gt[i]);
  est[0].world_from_cam.translation.x() += 1.0;
  const LocalizationAccuracy a = EvaluateLocalization(est, gt);
  EXPECT_EQ(a.matched, static_cast<int>(est.size()));
  EXPECT_EQ(a.step.front(), 0);
  EXPECT_EQ(a.converged_step, 1);  // an index into the estimate
  // No common timestamps.
  for (auto& p : est) p.timestamp += 0.5 / 30.0;
  EXPECT_THROW(EvaluateLocalization(est, gt), StageError);
}

TEST(LocalizationAccuracyTest, OptionsAreChecked) {
  const auto gt = GroundTruth(5);
  LocalizationAccuracyOptions o;
  o.max_translation_error_m = 0.0;
  EXPECT_THROW(EvaluateLocalization(gt, gt, o), OptionsError);
  o = LocalizationAccuracyOptions();
  o.max_rotation_error_deg = -1.0;
  EXPECT_THROW(o.Check(), OptionsError);
}

}  // namespace
}  // namespace monomap
