// Templated projection (plumb_bob or equidistant) shared by the
// triangulation refinement and bundle adjustment, so both minimise the same
// error: the distance in raw (distorted) pixels between a projected point
// and its observation. It mirrors Camera::ImageFromCam but works on
// ceres::Jet for autodiff.
#pragma once

#include <cmath>

#include "monomap/camera/camera.h"

namespace monomap::internal {

// Intrinsics as a flat array: fx, fy, cx, cy, then the camera's five
// distortion coefficients (plumb_bob k1, k2, p1, p2, k3; equidistant k1..k4,
// 0).
struct Intrinsics {
  double v[9];
  bool equidistant;
  explicit Intrinsics(const Camera& c)
      : v{c.fx,
          c.fy,
          c.cx,
          c.cy,
          c.distortion[0],
          c.distortion[1],
          c.distortion[2],
          c.distortion[3],
          c.distortion[4]},
        equidistant(c.model == LensModel::kEquidistant) {}
};

// Equidistant (Kannala-Brandt) normalized -> distorted: scales (x, y) by
// theta_d / r, which tends to 1 on the optical axis.
template <typename T, typename D>
inline void DistortEquidistant(const D* k, const T& x, const T& y, T* xd,
                               T* yd) {
  using std::atan;
  using std::sqrt;
  const T r2 = x * x + y * y;
  T scale(1.0);
  if (r2 > T(1e-24)) {
    const T r = sqrt(r2);
    const T theta = atan(r);
    const T t2 = theta * theta;
    scale =
        theta * (1.0 + t2 * (k[0] + t2 * (k[1] + t2 * (k[2] + t2 * k[3])))) / r;
  }
  *xd = x * scale;
  *yd = y * scale;
}

// Plumb_bob normalized -> distorted with k1, k2, p1, p2, k3.
template <typename T, typename D>
inline void DistortPlumbBob(const D* distortion, const T& x, const T& y, T* xd,
                            T* yd) {
  const D &k1 = distortion[0], &k2 = distortion[1], &p1 = distortion[2],
          &p2 = distortion[3], &k3 = distortion[4];
  const T r2 = x * x + y * y;
  const T radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
  *xd = x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x);
  *yd = y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y;
}

// Undistorted normalized (x, y) -> distorted normalized (*xd, *yd) with the
// five coefficients of the lens model (equidistant or plumb_bob).
template <typename T, typename D>
inline void DistortNormalized(bool equidistant, const D* distortion, const T& x,
                              const T& y, T* xd, T* yd) {
  if (equidistant) {
    DistortEquidistant(distortion, x, y, xd, yd);
  } else {
    DistortPlumbBob(distortion, x, y, xd, yd);
  }
}

// Camera-frame point -> raw pixel (px[0], px[1]) with the five distortion
// coefficients of the camera's lens model given apart (double, or ceres::Jet
// when bundle adjustment refines them). Caller checks z > 0.
template <typename T, typename D>
inline void ProjectWithDistortion(const Intrinsics& in, const D* distortion,
                                  const T* x_in_cam, T* px) {
  T xd, yd;
  DistortNormalized(in.equidistant, distortion, T(x_in_cam[0] / x_in_cam[2]),
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
