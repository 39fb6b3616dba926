#include "monomap/triangulation/point_trust.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "monomap/util/error.h"
#include "monomap/util/stats.h"

namespace monomap {

void PointTrustOptions::Check() const {
  CheckOption(min_track_length >= 2, "point_trust.min_track_length",
              "must be >= 2 (a point needs two views)");
  CheckOption(max_mean_reprojection_error_px > 0.0 &&
                  std::isfinite(max_mean_reprojection_error_px),
              "point_trust.max_mean_reprojection_error_px",
              "must be positive and finite");
  CheckOption(max_reprojection_error_median_ratio >= 0.0 &&
                  std::isfinite(max_reprojection_error_median_ratio),
              "point_trust.max_reprojection_error_median_ratio",
              "must be >= 0 and finite");
  CheckOption(
      min_triangulation_angle_deg >= 0.0 && min_triangulation_angle_deg < 180.0,
      "point_trust.min_triangulation_angle_deg", "must be in [0, 180)");
  CheckOption(std::isfinite(max_relative_uncertainty),
              "point_trust.max_relative_uncertainty", "must be finite");
}

namespace {

// Whether the point's own covariance is looser than the bound (false when
// the bound is off or the covariance unknown).
bool TooUncertain(const Landmark& l, double max_relative) {
  if (max_relative <= 0.0 || l.covariance_m2_per_px2.isZero()) return false;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(
      l.covariance_m2_per_px2, Eigen::EigenvaluesOnly);
  const double sigma = std::sqrt(std::max(eig.eigenvalues()(2), 0.0));
  // Written so that a NaN sigma or depth is too uncertain.
  return !(sigma <= max_relative * l.mean_depth_m);
}

// The mean reprojection error limit: the absolute one, or ratio x the
// points' median when that is smaller.
double ReprojectionLimit(const PointTrustOptions& options,
                         const std::vector<Landmark>& landmarks) {
  if (options.max_reprojection_error_median_ratio <= 0.0) {
    return options.max_mean_reprojection_error_px;
  }
  std::vector<double> errors;
  for (const Landmark& l : landmarks) {
    if (std::isfinite(l.mean_reprojection_error_px)) {
      errors.push_back(l.mean_reprojection_error_px);
    }
  }
  if (errors.empty()) return options.max_mean_reprojection_error_px;
  return std::min(options.max_mean_reprojection_error_px,
                  options.max_reprojection_error_median_ratio *
                      UpperMedian(std::move(errors)));
}

}  // namespace

PointTrustReport FilterTrustedPoints(const PointTrustOptions& options,
                                     std::vector<Landmark>* landmarks) {
  options.Check();
  PointTrustReport report;
  report.keep_all = options.keep_all;
  report.num_points = static_cast<int>(landmarks->size());
  report.reprojection_limit_px = ReprojectionLimit(options, *landmarks);
  size_t kept = 0;
  for (size_t i = 0; i < landmarks->size(); ++i) {
    const Landmark& l = (*landmarks)[i];
    // Written so that a NaN quality fails its test.
    bool trusted = false;
    if (l.num_observations < options.min_track_length) {
      ++report.short_track;
    } else if (!(l.mean_reprojection_error_px <=
                 report.reprojection_limit_px)) {
      ++report.reprojection_error;
    } else if (!(l.triangulation_angle_deg >=
                 options.min_triangulation_angle_deg)) {
      ++report.triangulation_angle;
    } else if (TooUncertain(l, options.max_relative_uncertainty)) {
      ++report.uncertainty;
    } else {
      trusted = true;
    }
    if (trusted || options.keep_all) {
      if (kept != i) (*landmarks)[kept] = std::move((*landmarks)[i]);
      ++kept;
    }
  }
  landmarks->resize(kept);
  report.num_exported = static_cast<int>(kept);
  return report;
}

}  // namespace monomap
