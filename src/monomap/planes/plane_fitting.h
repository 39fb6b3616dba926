// Stage 3 of map building: find the bounded planes that explain the
// triangulated landmarks.
//
// Sequential RANSAC: find the best plane among the remaining points (MSAC
// over optim/ransac.h with a per-point, depth-scaled inlier threshold),
// refine it by least squares while re-selecting inliers, split its inliers
// into spatially connected regions in the plane, accept the regions that are
// big enough as PlaneSegments, remove their points, repeat. Splitting makes
// a hypothesis through several objects fall apart into small pieces that
// are rejected, and coplanar but disconnected surfaces become separate
// segments.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "monomap/map/map.h"
#include "monomap/optim/ransac.h"

namespace monomap {

struct PlaneFittingOptions {
  // RANSAC hypotheses drawn per plane (2000, as in the original system).
  int ransac_iterations = 2000;
  // Seed of the RANSAC sampler; the output is a function of it.
  uint64_t seed = 42;
  // Inlier threshold of landmark i against a plane of normal n is
  // clamp(max(relative_threshold * mean_depth_m,
  //           covariance_sigmas * tracking_noise_px * sqrt(n^T C_i n)),
  //       min_threshold_m, max_threshold_m)
  // with C_i = Landmark::covariance_m2_per_px2: triangulation error grows
  // with depth, and much more along the rays of a point seen over a short
  // baseline, which a depth-only band would cut off its plane.
  double min_threshold_m = 0.002;
  // Threshold as a fraction of the landmark's mean depth.
  double relative_threshold = 0.01;
  // Effective noise of a tracked position (px), drift included, that scales
  // the landmark covariance; 0 disables the covariance term.
  double tracking_noise_px = 1.0;
  // Width of the covariance band in standard deviations.
  double covariance_sigmas = 3.0;
  // Upper bound of the threshold so far points cannot glue planes together.
  double max_threshold_m = 0.05;
  // Least-squares refinements (each re-selects inliers) after RANSAC.
  int refine_iterations = 3;
  // A segment needs at least max(min_inliers, min_inlier_fraction * number
  // of landmarks) points; smaller pieces are noise or clutter.
  int min_inliers = 30;
  // See min_inliers; scales the bar with the size of the point cloud.
  double min_inlier_fraction = 0.01;
  // Two inliers are neighbours (same connected region) if their in-plane
  // distance is below this; <= 0 selects the adaptive radius below.
  double connectivity_radius_m = 0.0;
  // Adaptive radius = this factor * median in-plane nearest-neighbour
  // spacing of the plane's inliers.
  double connectivity_factor = 4.0;
  // Bounds of the adaptive radius (m), guarding against degenerate spacing.
  double min_connectivity_radius_m = 0.005;
  // See min_connectivity_radius_m.
  double max_connectivity_radius_m = 1.0;
  // Maximum number of segments to output.
  int max_planes = 50;
  // Stop after this many hypotheses in a row give no acceptable segment:
  // what is left is noise. Their inliers are set aside meanwhile, so the
  // search moves on.
  int max_consecutive_failures = 3;
  // A new plane within this angle (deg) of an accepted segment whose inliers
  // lie on average within ghost_distance_factor x their threshold of that
  // segment's plane is a "ghost" (the segment's noisier points) and is
  // rejected; its points become outliers.
  double ghost_max_angle_deg = 3.0;
  // See ghost_max_angle_deg.
  double ghost_distance_factor = 3.0;
  // Polygon of a segment: false = convex hull of its inliers; true = the
  // outline of the occupancy grid of its inliers (follows concave shapes).
  bool concave_polygon = true;
  // Cell size of the occupancy grid for concave_polygon, as a factor of the
  // connectivity radius.
  double polygon_cell_factor = 0.5;

  void Check() const;
};

struct PlaneFittingReport {
  int num_points = 0;                  // landmarks in
  int num_planes = 0;                  // segments out
  std::vector<int> inliers_per_plane;  // per segment, same order
  int num_outliers = 0;                // landmarks on no segment
  int iterations = 0;                  // RANSAC hypotheses drawn in total
  int rejected_hypotheses = 0;         // planes with no big enough region
  int discarded_regions = 0;           // connected regions too small to keep
  double seconds = 0.0;                // wall-clock time
};

// Fits planes to `landmarks`, sets each landmark's plane_id to the id of its
// segment (-1 if on none) and replaces *segments (ids 0..n-1, in order of
// discovery). Each segment's frame has its origin at the inliers' centroid
// (projected) and u_axis along their principal in-plane direction; its
// polygon bounds the inliers. Normals point towards the cameras when
// `camera_centers` is given (n . C + d > 0 for most centres C); otherwise
// towards the world origin (offset >= 0). Landmarks with non-finite
// coordinates are outliers. Throws OptionsError for bad options.
PlaneFittingReport FitPlanes(
    const PlaneFittingOptions& options, std::vector<Landmark>* landmarks,
    std::vector<PlaneSegment>* segments,
    const std::vector<Eigen::Vector3d>* camera_centers = nullptr);

// Per-landmark inlier threshold of FitPlanes (see PlaneFittingOptions):
// the depth term is fixed, the covariance term depends on the normal.
struct PointThreshold {
  double depth_term_m = 0.0;  // relative_threshold * depth
  // Upper triangle of (k sigma)^2 C: xx, xy, xz, yy, yz, zz.
  std::array<double, 6> scaled_cov = {0, 0, 0, 0, 0, 0};
  double min_m = 0.0, max_m = 0.0;

  double operator()(const Eigen::Vector3d& n) const {
    const auto& c = scaled_cov;
    const double along = n.x() * (c[0] * n.x() + 2.0 * (c[1] * n.y() + c[2] * n.z())) +
                         n.y() * (c[3] * n.y() + 2.0 * c[4] * n.z()) +
                         n.z() * c[5] * n.z();
    return std::clamp(std::max(depth_term_m, std::sqrt(std::max(along, 0.0))),
                      min_m, max_m);
  }
};

// The threshold of a landmark under `options`.
PointThreshold MakePointThreshold(const PlaneFittingOptions& options,
                                  const Landmark& landmark);

// RANSAC estimator of a plane from 3 points whose residual is the distance
// divided by each point's own threshold along the model's normal, so
// Ransac() runs with inlier_threshold = 1.
struct PlaneEstimator {
  using Model = Plane;
  static constexpr int kSampleSize = 3;
  const std::vector<Eigen::Vector3d>* points = nullptr;
  const std::vector<PointThreshold>* thresholds = nullptr;

  size_t NumData() const { return points->size(); }
  void Fit(const std::vector<size_t>& sample,
           std::vector<Model>* models) const {
    Plane plane;
    if (Plane::FromPoints((*points)[sample[0]], (*points)[sample[1]],
                          (*points)[sample[2]], &plane)) {
      models->push_back(plane);
    }
  }
  double Residual(const Model& model, size_t i) const {
    return std::abs(model.SignedDistance((*points)[i])) /
           (*thresholds)[i](model.normal);
  }
};

}  // namespace monomap
