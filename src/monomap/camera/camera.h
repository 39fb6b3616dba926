// Pinhole camera with one of the two lens models of ROS camera_info:
//   plumb_bob    (Brown-Conrady, OpenCV's default) k1, k2, k3 radial,
//                p1, p2 tangential, applied to normalized coordinates;
//   equidistant  (Kannala-Brandt fisheye, OpenCV's cv::fisheye) k1..k4:
//                theta_d = theta (1 + k1 theta^2 + ... + k4 theta^8), with
//                theta the angle of the ray to the optical axis.
#pragma once

#include <array>
#include <optional>
#include <string>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace monomap {

enum class LensModel { kPlumbBob, kEquidistant };

// The camera_info name ("plumb_bob", "equidistant"); nullopt for others.
std::optional<LensModel> LensModelFromName(const std::string& name);
const char* LensModelName(LensModel model);

struct Camera {
  int width = 0;
  int height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;
  // plumb_bob: k1, k2, p1, p2, k3 (OpenCV order); equidistant: k1, k2, k3,
  // k4 and a 0.
  std::array<double, 5> distortion = {0, 0, 0, 0, 0};
  // Last, so that aggregate initializers of plumb_bob cameras stay valid.
  LensModel model = LensModel::kPlumbBob;

  bool HasDistortion() const;
  Eigen::Matrix3d K() const;

  // Normalized undistorted (x/z, y/z) -> normalized distorted.
  Eigen::Vector2d Distort(const Eigen::Vector2d& xn) const;
  // Inverse of Distort by Gauss-Newton (converges for real lenses within
  // the image); for equidistant, Newton on the angle, which stays below
  // kMaxEquidistantTheta.
  Eigen::Vector2d Undistort(const Eigen::Vector2d& xd) const;
  static constexpr double kMaxEquidistantTheta = 1.5607;  // 89.4 degrees

  // Camera-frame point -> raw (distorted) pixel. Caller checks z > 0.
  Eigen::Vector2d ImageFromCam(const Eigen::Vector3d& x_in_cam) const;
  // Raw pixel -> undistorted normalized coordinates (ray (x, y, 1)).
  Eigen::Vector2d NormalizedFromImage(const Eigen::Vector2d& px) const;
  // Undistorted normalized -> pixel of the ideal pinhole (no distortion).
  Eigen::Vector2d PinholeFromNormalized(const Eigen::Vector2d& xn) const {
    return {fx * xn.x() + cx, fy * xn.y() + cy};
  }

  bool InImage(const Eigen::Vector2d& px, double margin = 0.0) const {
    return px.x() >= -0.5 + margin && px.y() >= -0.5 + margin &&
           px.x() <= width - 0.5 - margin && px.y() <= height - 0.5 - margin;
  }

  // The same camera for images resized to new_width x new_height (pixel
  // centres convention: u' + 0.5 = s (u + 0.5)). Distortion is unchanged.
  Camera Scaled(int new_width, int new_height) const;
  // The same intrinsics without distortion, as plumb_bob (for rendering and
  // undistorted images).
  Camera Pinhole() const;

  // Throws OptionsError naming the field if a value makes no sense.
  void Check() const;

 private:
  Eigen::Vector2d UndistortEquidistant(const Eigen::Vector2d& xd) const;
};

}  // namespace monomap
