// Safe projection of camera-frame points through the distorted camera.
#pragma once

#include <Eigen/Core>

#include "monomap/camera/camera.h"

namespace monomap {

// Projects camera-frame points to raw (distorted) pixels, refusing points
// whose undistorted normalized coordinates lie far outside the image: there
// the plumb_bob polynomial folds back and would put far-away points inside
// the image.
class DistortedProjector {
 public:
  // `min_depth` (m): points with smaller z are not projected.
  explicit DistortedProjector(const Camera& camera, double min_depth = 1e-3);

  // Raw pixel of x_in_cam; false if behind the camera or outside the domain
  // where the distortion model is valid. Does not test InImage.
  bool Project(const Eigen::Vector3d& x_in_cam, Eigen::Vector2d* px) const {
    if (x_in_cam.z() < min_depth_) return false;
    return ProjectNormalized(x_in_cam.hnormalized(), px);
  }
  bool ProjectNormalized(const Eigen::Vector2d& xn, Eigen::Vector2d* px) const {
    if (xn.squaredNorm() > max_radius2_) return false;
    *px = camera_.PinholeFromNormalized(camera_.Distort(xn));
    return true;
  }
  const Camera& camera() const { return camera_; }

 private:
  Camera camera_;
  double min_depth_;
  double max_radius2_;  // squared normalized radius bound
};

}  // namespace monomap
