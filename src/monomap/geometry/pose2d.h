// Planar robot poses and the camera pose of a camera mounted on a planar
// robot base (the base frame's z = 0 lies on the floor, z up).
#pragma once

#include "monomap/geometry/rigid3.h"

namespace monomap {

// Planar robot base pose on the floor: position (m) and heading (rad).
struct Pose2d {
  double x = 0, y = 0, yaw = 0;
};

// world_from_cam of a camera mounted on a planar base (base z=0 on floor).
Rigid3d WorldFromCamOfBase(const Pose2d& base, const Rigid3d& base_from_cam);

// Robot base pose of a camera pose (inverse of WorldFromCamOfBase): the
// base frame's x, y and yaw; its height, roll and pitch are dropped.
Pose2d BaseOfWorldFromCam(const Rigid3d& world_from_cam,
                          const Rigid3d& base_from_cam);

}  // namespace monomap
