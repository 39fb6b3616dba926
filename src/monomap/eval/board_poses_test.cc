#include "monomap/eval/board_poses.h"

#include <gtest/gtest.h>

#include <cmath>

#include "monomap/camera/board_image_for_tests.h"
#include "monomap/util/angles.h"

namespace monomap {
namespace {

Camera TestCamera() {
  Camera c;
  c.width = 400;
  c.height = 300;
  c.fx = c.fy = 260.0;
  c.cx = 201.3;
  c.cy = 148.7;
  c.distortion = {-0.25, 0.06, 0.0, 0.0, 0.0};  // barrel, like the desk's
  return c;
}

// The spec's board (origin 0, axes x and y) seen from world_from_cam.
cv::Mat RenderBoard(const Camera& camera, const CheckerboardSpec& spec,
                    const Rigid3d& world_from_cam) {
  return testing::RenderCheckerboard(camera, spec.inner_corners_x,
                                     spec.inner_corners_y, spec.square_m,
                                     world_from_cam);
}

// Camera 0.35 m above the board centre, looking down at it (z of the board
// points away from the camera), tilted by `tilt_deg` about its x axis.
Rigid3d ViewOfBoard(double tilt_deg, double yaw_deg) {
  const Eigen::Quaterniond down(
      Eigen::AngleAxisd(DegToRad(yaw_deg), Eigen::Vector3d::UnitZ()) *
      Eigen::AngleAxisd(DegToRad(tilt_deg), Eigen::Vector3d::UnitX()));
  const Eigen::Vector3d centre(0.16, 0.10, 0.0);
  const Eigen::Vector3d c = centre - down * Eigen::Vector3d(0, 0, 0.35);
  return Rigid3d(down, c);
}

double RotationErrorDeg(const Rigid3d& a, const Rigid3d& b) {
  return RadToDeg(AngleBetween(a.rotation, b.rotation));
}

TEST(BoardPoses, RecoversTheCameraPoseOfARenderedBoard) {
  const Camera camera = TestCamera();
  const CheckerboardSpec spec;  // 9x6, 4 cm
  for (const auto& [tilt, yaw] : {std::pair{10.0, 5.0}, {-20.0, 30.0}}) {
    const Rigid3d truth = ViewOfBoard(tilt, yaw);
    const cv::Mat image = RenderBoard(camera, spec, truth);
    // A hint 5 degrees and 1 cm off, as a drifting odometry would give.
    const Rigid3d hint(
        truth.rotation *
            Eigen::AngleAxisd(DegToRad(5), Eigen::Vector3d::UnitY()),
        truth.translation + Eigen::Vector3d(0.01, 0, 0));
    const auto pose = EstimateBoardPose(image, camera, spec, hint, {});
    ASSERT_TRUE(pose.has_value()) << tilt;
    EXPECT_LT(RotationErrorDeg(pose->world_from_cam, truth), 0.05) << tilt;
    EXPECT_LT((pose->world_from_cam.translation - truth.translation).norm(),
              0.0005)
        << tilt;
    EXPECT_LT(pose->rms_px, 0.15);
    // The formal sigmas are small but not zero, and the actual error is
    // within a few of them.
    EXPECT_GT(pose->rotation_sigma_deg, 0.0);
    EXPECT_LT(RotationErrorDeg(pose->world_from_cam, truth),
              5 * pose->rotation_sigma_deg + 0.005);
  }
}

TEST(BoardPoses, TheHintResolvesTheHalfTurnOfTheBoard) {
  const Camera camera = TestCamera();
  const CheckerboardSpec spec;
  const Rigid3d truth = ViewOfBoard(8.0, 180.0);
  const cv::Mat image = RenderBoard(camera, spec, truth);
  // The board seen upside down: without the hint this is the half-turned
  // pose about the board centre.
  const auto pose = EstimateBoardPose(image, camera, spec, truth, {});
  ASSERT_TRUE(pose.has_value());
  EXPECT_LT(RotationErrorDeg(pose->world_from_cam, truth), 0.05);
  const Rigid3d turned = ViewOfBoard(8.0, 0.0);
  const auto other = EstimateBoardPose(image, camera, spec, turned, {});
  ASSERT_TRUE(other.has_value());
  EXPECT_GT(RotationErrorDeg(other->world_from_cam, truth), 179.0);
}

TEST(BoardPoses, NoBoardNoPose) {
  const Camera camera = TestCamera();
  const cv::Mat grey(camera.height, camera.width, CV_8UC1, cv::Scalar(128));
  EXPECT_FALSE(
      EstimateBoardPose(grey, camera, CheckerboardSpec(), Rigid3d(), {}));
}

TEST(BoardPoses, SequenceReportCountsFramesWithABoard) {
  const Camera camera = TestCamera();
  const CheckerboardSpec spec;
  const std::vector<Rigid3d> truth = {ViewOfBoard(5, 0), ViewOfBoard(12, 10)};
  const cv::Mat blank(camera.height, camera.width, CV_8UC1, cv::Scalar(128));
  const BoardPoseReport report = EstimateBoardPoses(
      [&](int i) {
        return i < 2 ? RenderBoard(camera, spec, truth[i]) : blank;
      },
      {0.1, 0.2, 0.3}, {truth[0], truth[1], truth[1]}, camera, spec, {});
  EXPECT_EQ(report.frames, 3);
  ASSERT_EQ(report.poses.size(), 2u);
  EXPECT_DOUBLE_EQ(report.poses[1].timestamp, 0.2);
  EXPECT_LT(RotationErrorDeg(report.poses[1].world_from_cam, truth[1]), 0.05);
  EXPECT_LT(report.rms_px.max, 0.15);
}

TEST(ExpressInAnchorFrameTest, TiesTheFirstPoseAndKeepsRelativeMotion) {
  std::vector<TimedPose> poses(2);
  poses[0].world_from_cam = Rigid3d(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ())),
      {1.0, 2.0, 3.0});
  poses[1].world_from_cam =
      poses[0].world_from_cam * Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(
                                            0.1, Eigen::Vector3d::UnitX())),
                                        {0.5, 0.0, 0.0});
  const Rigid3d relative =
      poses[0].world_from_cam.Inverse() * poses[1].world_from_cam;
  const Rigid3d anchor(
      Eigen::Quaterniond(Eigen::AngleAxisd(-1.0, Eigen::Vector3d::UnitY())),
      {-4.0, 0.0, 1.0});
  ExpressInAnchorFrame(anchor, &poses);
  EXPECT_LT((poses[0].world_from_cam.translation - anchor.translation).norm(),
            1e-12);
  EXPECT_LT(AngleBetween(poses[0].world_from_cam.rotation, anchor.rotation),
            1e-12);
  const Rigid3d after =
      poses[0].world_from_cam.Inverse() * poses[1].world_from_cam;
  EXPECT_LT((after.translation - relative.translation).norm(), 1e-12);
  EXPECT_LT(AngleBetween(after.rotation, relative.rotation), 1e-12);
}

}  // namespace
}  // namespace monomap
