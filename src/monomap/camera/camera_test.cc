#include "monomap/camera/camera.h"

#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>

namespace monomap {
namespace {

Camera DeskCamera() {
  Camera c;
  c.width = 752;
  c.height = 480;
  c.fx = 420.5;
  c.fy = 420.6;
  c.cx = 355.2;
  c.cy = 250.3;
  c.distortion = {-0.296609, 0.080818, 0.001, -0.0005, 0.0};
  return c;
}

TEST(Camera, UndistortInvertsDistortOverTheImage) {
  const Camera c = DeskCamera();
  double worst = 0.0;
  for (int v = 0; v < c.height; v += 20) {
    for (int u = 0; u < c.width; u += 20) {
      const Eigen::Vector2d px(u, v);
      const Eigen::Vector2d xn = c.NormalizedFromImage(px);
      const Eigen::Vector2d back = c.ImageFromCam(xn.homogeneous());
      worst = std::max(worst, (back - px).norm());
    }
  }
  EXPECT_LT(worst, 1e-6);
}

// A fisheye on a 640x480 sensor whose corners see 80 degrees off axis
// (k1..k4 of a typical calibration).
Camera FisheyeCamera() {
  Camera c;
  c.width = 640;
  c.height = 480;
  c.fx = 285.0;
  c.fy = 285.5;
  c.cx = 320.5;
  c.cy = 239.0;
  c.model = LensModel::kEquidistant;
  c.distortion = {0.021, -0.006, 0.0012, -0.0003, 0.0};
  return c;
}

TEST(Camera, EquidistantRoundTripsOverTheImage) {
  const Camera c = FisheyeCamera();
  double worst = 0.0, widest = 0.0;
  for (int v = 0; v < c.height; v += 16) {
    for (int u = 0; u < c.width; u += 16) {
      const Eigen::Vector2d px(u, v);
      const Eigen::Vector2d xn = c.NormalizedFromImage(px);
      const Eigen::Vector2d back = c.ImageFromCam(xn.homogeneous());
      worst = std::max(worst, (back - px).norm());
      widest = std::max(widest, std::atan(xn.norm()));
    }
  }
  EXPECT_LT(worst, 1e-6);
  // The corners see rays 60+ degrees off axis (pinhole would need a far
  // larger sensor).
  EXPECT_GT(widest * 180 / M_PI, 60.0);
}

TEST(Camera, EquidistantAgreesWithOpenCvFisheye) {
  const Camera c = FisheyeCamera();
  cv::Matx33d k(c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1);
  const cv::Vec4d d(c.distortion[0], c.distortion[1], c.distortion[2],
                    c.distortion[3]);
  std::vector<cv::Point3d> points;
  for (double x = -2.0; x <= 2.0; x += 0.25) {
    for (double y = -1.5; y <= 1.5; y += 0.25) points.push_back({x, y, 1.0});
  }
  std::vector<cv::Point2d> projected;
  cv::fisheye::projectPoints(points, projected, cv::Vec3d(0, 0, 0),
                             cv::Vec3d(0, 0, 0), k, d);
  double worst_project = 0.0, worst_unproject = 0.0;
  std::vector<cv::Point2d> undistorted;
  cv::fisheye::undistortPoints(projected, undistorted, k, d);
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d x(points[i].x, points[i].y, points[i].z);
    const Eigen::Vector2d p = c.ImageFromCam(x);
    worst_project =
        std::max(worst_project,
                 (p - Eigen::Vector2d(projected[i].x, projected[i].y)).norm());
    const Eigen::Vector2d xn = c.NormalizedFromImage(p);
    worst_unproject = std::max(
        worst_unproject,
        (xn - Eigen::Vector2d(undistorted[i].x, undistorted[i].y)).norm());
  }
  EXPECT_LT(worst_project, 1e-9);
  EXPECT_LT(worst_unproject, 1e-6);
}

TEST(Camera, EquidistantNamesAndChecks) {
  EXPECT_EQ(LensModelFromName("equidistant"), LensModel::kEquidistant);
  EXPECT_EQ(LensModelFromName("plumb_bob"), LensModel::kPlumbBob);
  EXPECT_FALSE(LensModelFromName("fisheye").has_value());
  Camera c = FisheyeCamera();
  EXPECT_TRUE(c.HasDistortion());
  c.distortion = {0, 0, 0, 0, 0};
  EXPECT_TRUE(c.HasDistortion());  // r = f theta is not a pinhole
  EXPECT_FALSE(c.Pinhole().HasDistortion());
  c.distortion[4] = 0.1;
  EXPECT_THROW(c.Check(), std::exception);
}

TEST(Camera, ScaledKeepsRaysThroughPixelCentres) {
  Camera c = DeskCamera().Pinhole();
  const Camera s = c.Scaled(188, 120);  // quarter size
  const Eigen::Vector3d x(0.3, -0.2, 1.7);
  const Eigen::Vector2d p = c.ImageFromCam(x);
  const Eigen::Vector2d q = s.ImageFromCam(x);
  EXPECT_NEAR(q.x() + 0.5, (p.x() + 0.5) / 4.0, 1e-9);
  EXPECT_NEAR(q.y() + 0.5, (p.y() + 0.5) / 4.0, 1e-9);
}

TEST(Camera, CheckNamesTheField) {
  Camera c = DeskCamera();
  c.fx = -1;
  try {
    c.Check();
    FAIL();
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("camera_matrix"), std::string::npos);
  }
}

}  // namespace
}  // namespace monomap
