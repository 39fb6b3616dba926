#include "monomap/geometry/rigid3.h"

#include <algorithm>
#include <cmath>

namespace monomap {

Eigen::Matrix<double, 3, 4> Rigid3d::ToMatrix3x4() const {
  Eigen::Matrix<double, 3, 4> m;
  m.leftCols<3>() = RotationMatrix();
  m.col(3) = translation;
  return m;
}

Eigen::Matrix4d Rigid3d::ToMatrix4() const {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topRows<3>() = ToMatrix3x4();
  return m;
}

double AngleBetween(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  const double d = std::abs(a.normalized().dot(b.normalized()));
  return 2.0 * std::acos(std::min(1.0, d));
}

Rigid3d Interpolate(const Rigid3d& a, const Rigid3d& b, double t) {
  return Rigid3d(a.rotation.slerp(t, b.rotation),
                 (1.0 - t) * a.translation + t * b.translation);
}

Eigen::Quaterniond QuaternionFromRotationVector(const Eigen::Vector3d& w) {
  const double angle = w.norm();
  if (angle < 1e-12) {
    // First-order expansion keeps tiny rotations exact enough and finite.
    return Eigen::Quaterniond(1.0, 0.5 * w.x(), 0.5 * w.y(), 0.5 * w.z())
        .normalized();
  }
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, w / angle));
}

Eigen::Vector3d RotationVectorFromQuaternion(const Eigen::Quaterniond& q) {
  Eigen::Quaterniond n = q.normalized();
  if (n.w() < 0) n.coeffs() *= -1.0;
  const Eigen::Vector3d v = n.vec();
  const double s = v.norm();
  if (s < 1e-12) return 2.0 * v;
  const double angle = 2.0 * std::atan2(s, n.w());
  return v * (angle / s);
}

Eigen::Quaterniond YawRotation(double yaw) {
  return Eigen::Quaterniond(
      Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
}

}  // namespace monomap
