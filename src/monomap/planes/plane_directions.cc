#include "monomap/planes/plane_directions.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>

namespace monomap {

namespace {

// Mean and scatter (sum of outer products about the mean) of the points.
struct Moments {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
};

// Weighted by 1 / sigma_i^2 (all 1 when `sigmas` is empty): the scatter's
// quadratic form n^T S n is then the chi-square sum of the residuals.
Moments WeightedMoments(const std::vector<Eigen::Vector3d>& x,
                        const std::vector<double>& sigmas) {
  Moments m;
  double total = 0.0;
  std::vector<double> w(x.size(), 1.0);
  for (size_t i = 0; i < x.size(); ++i) {
    if (!sigmas.empty()) w[i] = 1.0 / std::max(sigmas[i] * sigmas[i], 1e-18);
    m.mean += w[i] * x[i];
    total += w[i];
  }
  m.mean /= total;
  for (size_t i = 0; i < x.size(); ++i) {
    const Eigen::Vector3d d = x[i] - m.mean;
    m.scatter += w[i] * d * d.transpose();
  }
  return m;
}

// Points within band_sigmas of their sigma of the plane.
int CountWithinBand(const std::vector<Eigen::Vector3d>& x,
                    const std::vector<double>& sigmas, const Plane& plane,
                    double band_sigmas) {
  int n = 0;
  for (size_t i = 0; i < x.size(); ++i) {
    n += std::abs(plane.SignedDistance(x[i])) <= band_sigmas * sigmas[i];
  }
  return n;
}

// The residuals' standard deviation about the plane (sigmas unknown).
double UnitSigma(const std::vector<Eigen::Vector3d>& x, const Plane& plane) {
  double sq = 0.0;
  for (const auto& p : x) sq += std::pow(plane.SignedDistance(p), 2);
  return std::max(std::sqrt(sq / static_cast<double>(x.size() - 3)), 1e-9);
}

// Normal at right angles to d minimizing the residual of the scatter.
Eigen::Vector3d BestPerpendicular(const Eigen::Matrix3d& scatter,
                                  const Eigen::Vector3d& d) {
  Eigen::Matrix<double, 3, 2> basis;
  basis.col(0) = d.unitOrthogonal();
  basis.col(1) = d.cross(basis.col(0)).normalized();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(
      basis.transpose() * scatter * basis);
  return (basis * eig.eigenvectors().col(0)).normalized();
}

// A normal a segment may snap to, and how it was derived.
struct Candidate {
  Eigen::Vector3d normal;
  DirectionSnap::Kind kind;
  int dof;  // normal components it fixes
};

// Every direction, the best normal at right angles to each, and the cross
// product of every pair that is far from parallel.
std::vector<Candidate> Candidates(const Eigen::Matrix3d& scatter,
                                  const std::vector<Eigen::Vector3d>& dirs) {
  std::vector<Candidate> out;
  for (size_t i = 0; i < dirs.size(); ++i) {
    const Eigen::Vector3d di = dirs[i].normalized();
    out.push_back({di, DirectionSnap::Kind::kParallel, 2});
    out.push_back({BestPerpendicular(scatter, di),
                   DirectionSnap::Kind::kPerpendicular, 1});
    for (size_t j = i + 1; j < dirs.size(); ++j) {
      const Eigen::Vector3d c = di.cross(dirs[j].normalized());
      // Nearly parallel directions have no well-defined cross product.
      if (c.norm() < 0.5) continue;
      out.push_back({c.normalized(), DirectionSnap::Kind::kOrthogonal, 2});
    }
  }
  return out;
}

}  // namespace

const char* DirectionSnapKindName(DirectionSnap::Kind kind) {
  switch (kind) {
    case DirectionSnap::Kind::kParallel:
      return "parallel";
    case DirectionSnap::Kind::kPerpendicular:
      return "perpendicular";
    case DirectionSnap::Kind::kOrthogonal:
      return "orthogonal";
    case DirectionSnap::Kind::kNone:
      break;
  }
  return "none";
}

double NormalStandardErrorRad(const std::vector<Eigen::Vector3d>& x) {
  if (x.size() < 4) return std::numeric_limits<double>::infinity();
  const Moments m = WeightedMoments(x, {});
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(m.scatter);
  const Eigen::Vector3d ev = eig.eigenvalues().cwiseMax(0.0);
  if (ev(1) <= 0) return std::numeric_limits<double>::infinity();
  const double sigma2 = ev(0) / static_cast<double>(x.size() - 3);
  return std::sqrt(sigma2 / ev(1));
}

DirectionSnap SnapToDirections(const std::vector<Eigen::Vector3d>& x,
                               const std::vector<double>& sigmas,
                               const std::vector<Eigen::Vector3d>& directions,
                               const DirectionSnapOptions& options) {
  DirectionSnap best;
  best.plane = FitPlaneLeastSquares(x);
  if (x.size() < 4 || directions.empty()) return best;
  const std::vector<double> sig =
      sigmas.empty() ? std::vector<double>(x.size(), UnitSigma(x, best.plane))
                     : sigmas;
  const Eigen::Vector3d free_normal = best.plane.normal;
  const int free_kept = CountWithinBand(x, sig, best.plane, options.band_sigmas);
  const Moments m = WeightedMoments(x, sig);
  for (const Candidate& c : Candidates(m.scatter, directions)) {
    const double angle =
        std::acos(std::min(1.0, std::abs(c.normal.dot(free_normal))));
    if (angle > options.max_angle_rad) continue;
    const Eigen::Vector3d n =
        c.normal.dot(free_normal) < 0 ? -c.normal : c.normal;
    const Plane plane{n, -n.dot(m.mean)};
    const int kept = CountWithinBand(x, sig, plane, options.band_sigmas);
    if (kept < options.min_kept_fraction * free_kept) continue;
    const double rss = n.dot(m.scatter * n);
    const bool better =
        best.kind == DirectionSnap::Kind::kNone || c.dof > best.dof ||
        (c.dof == best.dof && rss < best.weighted_rss);
    if (!better) continue;
    best.kind = c.kind;
    best.dof = c.dof;
    best.weighted_rss = rss;
    best.kept_fraction = free_kept > 0 ? static_cast<double>(kept) / free_kept
                                       : 1.0;
    best.angle_deg = angle * 180.0 / M_PI;
    best.plane = plane;
  }
  return best;
}

}  // namespace monomap
