// Templated plumb_bob projection shared by the triangulation refinement and
// bundle adjustment, so both minimise the same error: the distance in raw
// (distorted) pixels between a projected point and its observation. It
// mirrors Camera::ImageFromCam but works on ceres::Jet for autodiff.
#pragma once

#include "monomap/camera/camera.h"

namespace monomap::internal {

// Intrinsics as a flat array: fx, fy, cx, cy, k1, k2, p1, p2, k3.
struct Intrinsics {
  double v[9];
  explicit Intrinsics(const Camera& c)
      : v{c.fx,
          c.fy,
          c.cx,
          c.cy,
          c.distortion[0],
          c.distortion[1],
          c.distortion[2],
          c.distortion[3],
          c.distortion[4]} {}
};

// Camera-frame point -> raw pixel (px[0], px[1]) with the distortion
// coefficients k1, k2, p1, p2, k3 given apart (double, or ceres::Jet when
// bundle adjustment refines them). Caller checks z > 0.
// Undistorted normalized (x, y) -> distorted normalized (*xd, *yd) with the
// plumb_bob coefficients k1, k2, p1, p2, k3.
template <typename T, typename D>
inline void DistortNormalized(const D* distortion, const T& x, const T& y,
                              T* xd, T* yd) {
  const D &k1 = distortion[0], &k2 = distortion[1], &p1 = distortion[2],
          &p2 = distortion[3], &k3 = distortion[4];
  const T r2 = x * x + y * y;
  const T radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
  *xd = x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x);
  *yd = y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y;
}

// Camera-frame point -> raw pixel (px[0], px[1]) with the distortion
// coefficients k1, k2, p1, p2, k3 given apart (double, or ceres::Jet when
// bundle adjustment refines them). Caller checks z > 0.
template <typename T, typename D>
inline void ProjectWithDistortion(const Intrinsics& in, const D* distortion,
                                  const T* x_in_cam, T* px) {
  T xd, yd;
  DistortNormalized(distortion, T(x_in_cam[0] / x_in_cam[2]),
                    T(x_in_cam[1] / x_in_cam[2]), &xd, &yd);
  px[0] = in.v[0] * xd + in.v[2];
  px[1] = in.v[1] * yd + in.v[3];
}

// The same with the camera's own distortion.
template <typename T>
inline void ProjectToImage(const Intrinsics& in, const T* x_in_cam, T* px) {
  ProjectWithDistortion(in, in.v + 4, x_in_cam, px);
}

}  // namespace monomap::internal
