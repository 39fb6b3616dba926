// Rigid-body transforms in 3D. Names say which frame maps to which:
// `world_from_cam` maps camera coordinates to world coordinates, so
// x_in_world = world_from_cam * x_in_cam. TUM trajectory files hold
// world_from_cam (camera-to-world).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace monomap {

struct Rigid3d {
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Rigid3d() = default;
  Rigid3d(const Eigen::Quaterniond& q, const Eigen::Vector3d& t)
      : rotation(q.normalized()), translation(t) {}

  static Rigid3d Identity() { return Rigid3d(); }

  Eigen::Vector3d operator*(const Eigen::Vector3d& x) const {
    return rotation * x + translation;
  }
  Rigid3d operator*(const Rigid3d& other) const {
    return Rigid3d(rotation * other.rotation,
                   rotation * other.translation + translation);
  }
  Rigid3d Inverse() const {
    const Eigen::Quaterniond inv = rotation.conjugate();
    return Rigid3d(inv, -(inv * translation));
  }
  Eigen::Matrix3d RotationMatrix() const {
    return rotation.toRotationMatrix();
  }
  // 3x4 matrix [R | t].
  Eigen::Matrix<double, 3, 4> ToMatrix3x4() const;
  Eigen::Matrix4d ToMatrix4() const;
};

// Rotation angle between two rotations, in radians.
double AngleBetween(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b);

// Interpolates between poses: t=0 gives a, t=1 gives b (slerp on rotation,
// linear on translation).
Rigid3d Interpolate(const Rigid3d& a, const Rigid3d& b, double t);

// SO(3) exponential and logarithm with the axis-angle vector.
Eigen::Quaterniond QuaternionFromRotationVector(const Eigen::Vector3d& w);
Eigen::Vector3d RotationVectorFromQuaternion(const Eigen::Quaterniond& q);

// Rotation about +z by `yaw` radians.
Eigen::Quaterniond YawRotation(double yaw);

}  // namespace monomap
