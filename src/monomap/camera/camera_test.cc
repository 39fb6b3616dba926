#include "monomap/camera/camera.h"

#include <gtest/gtest.h>

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
