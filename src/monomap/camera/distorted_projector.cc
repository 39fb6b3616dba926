#include "monomap/camera/distorted_projector.h"

#include <algorithm>

namespace monomap {

DistortedProjector::DistortedProjector(const Camera& camera, double min_depth)
    : camera_(camera), min_depth_(min_depth) {
  // Largest undistorted radius of the image border, with 25% slack: points
  // beyond it cannot land in the image, and the distortion polynomial is
  // not monotonic far outside it.
  double r2 = 0.0;
  const double w = camera.width - 0.5, h = camera.height - 0.5;
  constexpr int kSteps = 16;
  for (int i = 0; i <= kSteps; ++i) {
    const double a = -0.5 + (w + 0.5) * i / kSteps;
    const double b = -0.5 + (h + 0.5) * i / kSteps;
    for (const Eigen::Vector2d& px :
         {Eigen::Vector2d(a, -0.5), Eigen::Vector2d(a, h),
          Eigen::Vector2d(-0.5, b), Eigen::Vector2d(w, b)}) {
      r2 = std::max(r2, camera.NormalizedFromImage(px).squaredNorm());
    }
  }
  max_radius2_ = r2 * 1.25 * 1.25;
}

}  // namespace monomap
