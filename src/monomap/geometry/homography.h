// Plane-induced homographies between images and plane coordinates.
#pragma once

#include <Eigen/Core>

#include "monomap/geometry/plane.h"
#include "monomap/geometry/rigid3.h"

namespace monomap {

// Homography mapping plane coordinates (s, t, 1) of `frame` to normalized
// image coordinates (x/z, y/z, 1) of a camera with pose cam_from_world.
// Multiply on the left by the intrinsic matrix K for pixels.
Eigen::Matrix3d NormalizedImageFromPlane(const Rigid3d& cam_from_world,
                                         const PlaneFrame& frame);

// Applies a homography to a 2D point.
inline Eigen::Vector2d ApplyHomography(const Eigen::Matrix3d& h,
                                       const Eigen::Vector2d& x) {
  const Eigen::Vector3d y = h * x.homogeneous();
  return y.hnormalized();
}

}  // namespace monomap
