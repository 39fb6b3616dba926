#include "monomap/geometry/plane.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "monomap/util/error.h"

namespace monomap {

bool Plane::FromPoints(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                       const Eigen::Vector3d& c, Plane* plane) {
  const Eigen::Vector3d n = (b - a).cross(c - a);
  const double norm = n.norm();
  const double scale = std::max({(b - a).norm(), (c - a).norm(), 1e-12});
  if (norm < 1e-9 * scale * scale) return false;
  plane->normal = n / norm;
  plane->offset = -plane->normal.dot(a);
  return true;
}

Plane Plane::Transformed(const Rigid3d& t) const {
  Plane p;
  p.normal = t.rotation * normal;
  p.offset = offset - p.normal.dot(t.translation);
  return p;
}

Plane FitPlaneLeastSquares(const std::vector<Eigen::Vector3d>& points) {
  if (points.size() < 3) {
    throw StageError("plane fit needs at least 3 points, got " +
                     std::to_string(points.size()));
  }
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const auto& p : points) {
    const Eigen::Vector3d d = p - mean;
    scatter += d * d.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(scatter);
  Plane plane;
  plane.normal = solver.eigenvectors().col(0).normalized();
  plane.offset = -plane.normal.dot(mean);
  return plane;
}

double PlaneAngle(const Plane& a, const Plane& b) {
  const double c = std::abs(a.normal.normalized().dot(b.normal.normalized()));
  return std::acos(std::min(1.0, c));
}

PlaneFrame MakePlaneFrame(const Plane& plane, const Eigen::Vector3d& near,
                          const Eigen::Vector3d& u_hint) {
  PlaneFrame f;
  const Eigen::Vector3d n = plane.normal.normalized();
  f.origin = plane.Project(near);
  Eigen::Vector3d u = u_hint - u_hint.dot(n) * n;
  if (u.norm() < 1e-6) {
    u = n.unitOrthogonal();
  }
  f.u_axis = u.normalized();
  f.v_axis = n.cross(f.u_axis).normalized();
  return f;
}

}  // namespace monomap
