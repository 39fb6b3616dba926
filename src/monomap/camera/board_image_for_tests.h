// Test helper: the image of a flat checkerboard seen by a camera, rendered
// exactly (each pixel's ray intersected with the board, 4x4 samples per
// pixel, the camera's distortion included). Used by the calibration and
// board-pose tests.
#pragma once

#include <cmath>
#include <opencv2/core.hpp>

#include "monomap/camera/camera.h"
#include "monomap/geometry/rigid3.h"

namespace monomap::testing {

// Board in the world plane z = 0, inner corner (i, j) at
// (i * square_m, j * square_m, 0); black squares, a white margin of one
// square, grey beyond.
inline cv::Mat RenderCheckerboard(const Camera& camera, int inner_corners_x,
                                  int inner_corners_y, double square_m,
                                  const Rigid3d& world_from_cam) {
  cv::Mat image(camera.height, camera.width, CV_8UC1);
  const Eigen::Matrix3d r = world_from_cam.RotationMatrix();
  const Eigen::Vector3d c = world_from_cam.translation;
  for (int v = 0; v < camera.height; ++v) {
    for (int u = 0; u < camera.width; ++u) {
      double sum = 0.0;
      for (int sv = 0; sv < 4; ++sv) {
        for (int su = 0; su < 4; ++su) {
          const Eigen::Vector2d xn = camera.NormalizedFromImage(
              {u - 0.375 + 0.25 * su, v - 0.375 + 0.25 * sv});
          const Eigen::Vector3d ray = r * Eigen::Vector3d(xn.x(), xn.y(), 1);
          const double s = -c.z() / ray.z();
          const Eigen::Vector3d x = c + s * ray;
          const double a = x.x() / square_m, b = x.y() / square_m;
          const bool board = s > 0 && a > -2 && b > -2 &&
                             a < inner_corners_x + 1 && b < inner_corners_y + 1;
          const bool square =
              a > -1 && b > -1 && a < inner_corners_x && b < inner_corners_y;
          const bool black = square && (static_cast<int>(std::floor(a)) +
                                        static_cast<int>(std::floor(b))) %
                                               2 ==
                                           0;
          sum += !board ? 120.0 : black ? 20.0 : 235.0;
        }
      }
      image.at<uchar>(v, u) = static_cast<uchar>(std::lround(sum / 16.0));
    }
  }
  return image;
}

}  // namespace monomap::testing
