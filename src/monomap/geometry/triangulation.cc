#include "monomap/geometry/triangulation.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

namespace monomap {

bool TriangulateLinear(const std::vector<Rigid3d>& cams_from_world,
                       const std::vector<Eigen::Vector2d>& normalized,
                       Eigen::Vector3d* x_in_world) {
  const size_t n = cams_from_world.size();
  if (n < 2 || normalized.size() != n) return false;
  Eigen::MatrixXd a(2 * n, 4);
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Matrix<double, 3, 4> p = cams_from_world[i].ToMatrix3x4();
    a.row(2 * i) = normalized[i].x() * p.row(2) - p.row(0);
    a.row(2 * i + 1) = normalized[i].y() * p.row(2) - p.row(1);
  }
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(a, Eigen::ComputeFullV);
  const Eigen::Vector4d x = svd.matrixV().col(3);
  if (std::abs(x(3)) < 1e-12) return false;
  *x_in_world = x.head<3>() / x(3);
  return x_in_world->allFinite();
}

double MaxTriangulationAngle(const std::vector<Rigid3d>& cams_from_world,
                             const Eigen::Vector3d& x_in_world) {
  std::vector<Eigen::Vector3d> rays;
  rays.reserve(cams_from_world.size());
  for (const auto& c : cams_from_world) {
    const Eigen::Vector3d center = c.Inverse().translation;
    rays.push_back((x_in_world - center).normalized());
  }
  // Two sweeps (farthest ray from the first, then farthest from that) give
  // the largest pairwise angle in O(n) for rays within a hemisphere.
  auto farthest = [&](size_t from, double* angle) {
    size_t arg = from;
    *angle = 0.0;
    for (size_t i = 0; i < rays.size(); ++i) {
      const double a = std::acos(std::clamp(rays[from].dot(rays[i]), -1.0, 1.0));
      if (a > *angle) {
        *angle = a;
        arg = i;
      }
    }
    return arg;
  };
  if (rays.size() < 2) return 0.0;
  double best = 0.0;
  const size_t j = farthest(0, &best);
  farthest(j, &best);
  return best;
}

}  // namespace monomap
