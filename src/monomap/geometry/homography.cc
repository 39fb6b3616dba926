#include "monomap/geometry/homography.h"

namespace monomap {

Eigen::Matrix3d NormalizedImageFromPlane(const Rigid3d& cam_from_world,
                                         const PlaneFrame& frame) {
  // x_cam = R (origin + s u + t v) + T = [R u, R v, R origin + T] (s, t, 1).
  const Eigen::Matrix3d r = cam_from_world.RotationMatrix();
  Eigen::Matrix3d h;
  h.col(0) = r * frame.u_axis;
  h.col(1) = r * frame.v_axis;
  h.col(2) = r * frame.origin + cam_from_world.translation;
  return h;
}

}  // namespace monomap
