#include "monomap/camera/camera.h"

#include <algorithm>
#include <cmath>

#include "monomap/util/error.h"

namespace monomap {

std::optional<LensModel> LensModelFromName(const std::string& name) {
  if (name == "plumb_bob") return LensModel::kPlumbBob;
  if (name == "equidistant") return LensModel::kEquidistant;
  return std::nullopt;
}

const char* LensModelName(LensModel model) {
  return model == LensModel::kEquidistant ? "equidistant" : "plumb_bob";
}

bool Camera::HasDistortion() const {
  // The equidistant projection bends rays even with k1..k4 = 0.
  if (model == LensModel::kEquidistant) return true;
  for (double d : distortion) {
    if (d != 0.0) return true;
  }
  return false;
}

Eigen::Matrix3d Camera::K() const {
  Eigen::Matrix3d k;
  k << fx, 0, cx, 0, fy, cy, 0, 0, 1;
  return k;
}

namespace {

// Kannala-Brandt: theta -> theta_d, and its derivative.
double EquidistantTheta(const std::array<double, 5>& k, double theta,
                        double* derivative) {
  const double t2 = theta * theta;
  const double poly = 1.0 + t2 * (k[0] + t2 * (k[1] + t2 * (k[2] + t2 * k[3])));
  if (derivative) {
    *derivative =
        1.0 +
        t2 * (3 * k[0] + t2 * (5 * k[1] + t2 * (7 * k[2] + t2 * 9 * k[3])));
  }
  return theta * poly;
}

}  // namespace

Eigen::Vector2d Camera::Distort(const Eigen::Vector2d& xn) const {
  if (model == LensModel::kEquidistant) {
    const double r = xn.norm();
    if (r < 1e-12) return xn;  // theta_d / r -> 1 on the axis
    return xn * (EquidistantTheta(distortion, std::atan(r), nullptr) / r);
  }
  const double k1 = distortion[0], k2 = distortion[1], p1 = distortion[2],
               p2 = distortion[3], k3 = distortion[4];
  const double x = xn.x(), y = xn.y();
  const double r2 = x * x + y * y;
  const double radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
  return {x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x),
          y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y};
}

Eigen::Vector2d Camera::UndistortEquidistant(const Eigen::Vector2d& xd) const {
  const double theta_d = xd.norm();
  if (theta_d < 1e-12) return xd;
  // Newton on theta_d(theta) = theta_d, from theta = theta_d; the angle
  // stays below 90 degrees (rays behind the lens plane are not images).
  double theta = std::min(theta_d, kMaxEquidistantTheta);
  for (int iter = 0; iter < 20; ++iter) {
    double slope = 0;
    const double f = EquidistantTheta(distortion, theta, &slope) - theta_d;
    if (std::abs(f) < 1e-14 || slope <= 0) break;
    theta = std::clamp(theta - f / slope, 0.0, kMaxEquidistantTheta);
  }
  return xd * (std::tan(theta) / theta_d);
}

Eigen::Vector2d Camera::Undistort(const Eigen::Vector2d& xd) const {
  if (!HasDistortion()) return xd;
  if (model == LensModel::kEquidistant) return UndistortEquidistant(xd);
  Eigen::Vector2d x = xd;
  for (int iter = 0; iter < 20; ++iter) {
    const Eigen::Vector2d r = Distort(x) - xd;
    if (r.squaredNorm() < 1e-24) break;
    // Numeric Jacobian: cheap and exact enough for a 2x2 Newton step.
    constexpr double kEps = 1e-7;
    Eigen::Matrix2d j;
    j.col(0) = (Distort(x + Eigen::Vector2d(kEps, 0)) - Distort(x)) / kEps;
    j.col(1) = (Distort(x + Eigen::Vector2d(0, kEps)) - Distort(x)) / kEps;
    x -= j.inverse() * r;
  }
  return x;
}

Eigen::Vector2d Camera::ImageFromCam(const Eigen::Vector3d& x_in_cam) const {
  const Eigen::Vector2d xd = Distort(x_in_cam.hnormalized());
  return {fx * xd.x() + cx, fy * xd.y() + cy};
}

Eigen::Vector2d Camera::NormalizedFromImage(const Eigen::Vector2d& px) const {
  return Undistort({(px.x() - cx) / fx, (px.y() - cy) / fy});
}

Camera Camera::Scaled(int new_width, int new_height) const {
  Camera c = *this;
  const double sx = static_cast<double>(new_width) / width;
  const double sy = static_cast<double>(new_height) / height;
  c.width = new_width;
  c.height = new_height;
  c.fx = fx * sx;
  c.fy = fy * sy;
  c.cx = (cx + 0.5) * sx - 0.5;
  c.cy = (cy + 0.5) * sy - 0.5;
  return c;
}

Camera Camera::Pinhole() const {
  Camera c = *this;
  c.model = LensModel::kPlumbBob;
  c.distortion = {0, 0, 0, 0, 0};
  return c;
}

void Camera::Check() const {
  CheckOption(width > 0 && height > 0, "camera.image_width/image_height",
              "must be positive");
  CheckOption(std::isfinite(fx) && fx > 0 && std::isfinite(fy) && fy > 0,
              "camera.camera_matrix", "focal lengths must be positive");
  CheckOption(std::isfinite(cx) && std::isfinite(cy), "camera.camera_matrix",
              "principal point must be finite");
  for (double d : distortion) {
    CheckOption(std::isfinite(d), "camera.distortion_coefficients",
                "must be finite");
  }
  CheckOption(model != LensModel::kEquidistant || distortion[4] == 0.0,
              "camera.distortion_coefficients",
              "equidistant has 4 coefficients (k1..k4)");
}

}  // namespace monomap
