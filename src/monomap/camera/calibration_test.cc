#include "monomap/camera/calibration.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "monomap/camera/board_image_for_tests.h"
#include "monomap/util/angles.h"
#include "monomap/util/error.h"

namespace monomap {
namespace {

Camera TrueCamera() {
  Camera c;
  c.width = 400;
  c.height = 300;
  c.fx = 262.0;
  c.fy = 261.0;
  c.cx = 198.5;
  c.cy = 152.0;
  c.distortion = {-0.28, 0.09, 0.0005, -0.0008, -0.02};
  return c;
}

// Views of the 9x6 board (4 cm squares) from 0.3-0.4 m, tilted and turned
// so that its corners reach the image's rim in some of them.
std::vector<Rigid3d> Views() {
  std::vector<Rigid3d> views;
  for (int k = 0; k < 14; ++k) {
    const double tilt = -25.0 + 50.0 * (k % 5) / 4.0;
    const double roll = -30.0 + 60.0 * (k % 3) / 2.0;
    const double yaw = 20.0 * k;
    const Eigen::Quaterniond look(
        Eigen::AngleAxisd(DegToRad(yaw), Eigen::Vector3d::UnitZ()) *
        Eigen::AngleAxisd(DegToRad(tilt), Eigen::Vector3d::UnitX()) *
        Eigen::AngleAxisd(DegToRad(roll), Eigen::Vector3d::UnitY()));
    const Eigen::Vector3d centre(0.16 + 0.02 * std::sin(k), 0.10, 0.0);
    const double distance = 0.3 + 0.1 * (k % 2);
    views.emplace_back(look, centre - look * Eigen::Vector3d(0, 0, distance));
  }
  return views;
}

TEST(Calibration, RecoversTheLensFromRenderedBoards) {
  const Camera truth = TrueCamera();
  const std::vector<Rigid3d> views = Views();
  std::vector<cv::Mat> images;
  for (const Rigid3d& v : views) {
    images.push_back(testing::RenderCheckerboard(truth, 9, 6, 0.04, v));
  }
  // A calibration 1 % off in focal length and with too weak a barrel.
  Camera initial = truth;
  initial.fx *= 1.01;
  initial.fy *= 1.01;
  initial.distortion = {-0.24, 0.05, 0.0, 0.0, 0.0};
  CalibrationOptions options;
  options.stride = 1;
  const CalibrationReport report = CalibrateFromCheckerboard(
      [&](int i) { return images[i]; }, static_cast<int>(images.size()),
      initial, options);
  std::printf("views %d, rms %.3f -> %.3f px, f %.2f %.2f, k %.4f %.4f %.4f\n",
              report.views, report.initial_rms_px, report.final_rms_px,
              report.camera.fx, report.camera.fy, report.camera.distortion[0],
              report.camera.distortion[1], report.camera.distortion[4]);
  // Measured: 10 views, 0.263 -> 0.057 px (per-view poses absorb much of
  // a wrong lens, which is why the rim test below matters).
  EXPECT_GE(report.views, 9);
  EXPECT_GT(report.max_corner_radius_px, 150.0);
  EXPECT_GT(report.initial_rms_px, 0.2);
  EXPECT_LT(report.final_rms_px, 0.08);
  EXPECT_LT(report.final_rms_px, report.initial_rms_px / 3.0);
  EXPECT_NEAR(report.camera.fx, truth.fx, 0.5);
  EXPECT_NEAR(report.camera.fy, truth.fy, 0.5);
  EXPECT_NEAR(report.camera.cx, truth.cx, 0.5);
  EXPECT_NEAR(report.camera.cy, truth.cy, 0.5);
  // What matters is where rays land: within 0.3 px (measured 0.13-0.22, a
  // principal point ~0.2 px off) out to the board's reach, while the
  // initial calibration is pixels off there.
  for (const Eigen::Vector3d& x :
       {Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0.4, 0.3, 1),
        Eigen::Vector3d(-0.5, 0.2, 1), Eigen::Vector3d(0.3, -0.4, 1)}) {
    const Eigen::Vector2d true_px = truth.ImageFromCam(x);
    EXPECT_LT((report.camera.ImageFromCam(x) - true_px).norm(), 0.3)
        << x.transpose();
  }
  EXPECT_GT(
      (initial.ImageFromCam({0.4, 0.3, 1}) - truth.ImageFromCam({0.4, 0.3, 1}))
          .norm(),
      1.0);
}

TEST(Calibration, TooFewViewsOfTheBoardIsAnError) {
  const Camera truth = TrueCamera();
  const cv::Mat blank(truth.height, truth.width, CV_8UC1, cv::Scalar(128));
  CalibrationOptions options;
  options.stride = 1;
  EXPECT_THROW(
      CalibrateFromCheckerboard([&](int) { return blank; }, 20, truth, options),
      StageError);
}

}  // namespace
}  // namespace monomap
