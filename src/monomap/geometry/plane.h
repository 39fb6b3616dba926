// Infinite planes n . X + d = 0 and their in-plane coordinate frames.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "monomap/geometry/rigid3.h"

namespace monomap {

struct Plane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit length
  double offset = 0.0;                                 // n . X + offset = 0

  double SignedDistance(const Eigen::Vector3d& x) const {
    return normal.dot(x) + offset;
  }
  // Plane through three points; returns false if they are (nearly)
  // collinear.
  static bool FromPoints(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                         const Eigen::Vector3d& c, Plane* plane);
  // Transforms the plane: if X' = T * X, returns the plane of the X'.
  Plane Transformed(const Rigid3d& t) const;
  Eigen::Vector3d Project(const Eigen::Vector3d& x) const {
    return x - SignedDistance(x) * normal;
  }
};

// Total least-squares plane through points (smallest-eigenvalue normal of
// the scatter matrix). Needs >= 3 points; throws StageError otherwise.
Plane FitPlaneLeastSquares(const std::vector<Eigen::Vector3d>& points);

// Angle between plane normals, ignoring orientation, in radians.
double PlaneAngle(const Plane& a, const Plane& b);

// An orthonormal in-plane frame: X = origin + s * u_axis + t * v_axis for
// points on the plane; u x v = normal.
struct PlaneFrame {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d u_axis = Eigen::Vector3d::UnitX();
  Eigen::Vector3d v_axis = Eigen::Vector3d::UnitY();

  Eigen::Vector3d ToWorld(const Eigen::Vector2d& st) const {
    return origin + st.x() * u_axis + st.y() * v_axis;
  }
  Eigen::Vector2d ToPlane(const Eigen::Vector3d& x) const {
    const Eigen::Vector3d d = x - origin;
    return {d.dot(u_axis), d.dot(v_axis)};
  }
  Eigen::Vector3d Normal() const { return u_axis.cross(v_axis); }
};

// A frame on `plane` with origin the projection of `near` and u_axis the
// projection of `u_hint` (or any perpendicular direction if degenerate).
PlaneFrame MakePlaneFrame(const Plane& plane, const Eigen::Vector3d& near,
                          const Eigen::Vector3d& u_hint);

}  // namespace monomap
