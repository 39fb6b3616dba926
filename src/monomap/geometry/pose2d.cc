#include "monomap/geometry/pose2d.h"

#include <cmath>

namespace monomap {

Rigid3d WorldFromCamOfBase(const Pose2d& base, const Rigid3d& base_from_cam) {
  const Rigid3d world_from_base(YawRotation(base.yaw),
                                Eigen::Vector3d(base.x, base.y, 0.0));
  return world_from_base * base_from_cam;
}

Pose2d BaseOfWorldFromCam(const Rigid3d& world_from_cam,
                          const Rigid3d& base_from_cam) {
  const Rigid3d world_from_base = world_from_cam * base_from_cam.Inverse();
  const Eigen::Matrix3d r = world_from_base.RotationMatrix();
  return {world_from_base.translation.x(), world_from_base.translation.y(),
          std::atan2(r(1, 0), r(0, 0))};
}

}  // namespace monomap
