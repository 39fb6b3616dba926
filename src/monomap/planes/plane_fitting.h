// Stage 3 of map building: find the bounded planes that explain the
// triangulated landmarks.
//
// Sequential RANSAC: find the best plane among the remaining points (MSAC
// over optim/ransac.h with a per-point, depth-scaled inlier threshold),
// refine it by least squares while re-selecting inliers, split its inliers
// into spatially connected regions in the plane, accept the regions that are
// big enough as PlaneSegments, remove their points together with the points
// that are consistent with an accepted segment within their own
// uncertainty (see absorb_consistent_points), repeat. Splitting makes
// a hypothesis through several objects fall apart into small pieces that
// are rejected, and coplanar but disconnected surfaces become separate
// segments.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "monomap/map/map.h"
#include "monomap/optim/ransac.h"

namespace monomap {

struct PlaneFittingOptions {
  // RANSAC hypotheses drawn per plane (2000, as in the original system).
  int ransac_iterations = 2000;
  // Seed of the RANSAC sampler; the output is a function of it.
  uint64_t seed = 42;
  // Inlier threshold of landmark i is clamp(relative_threshold *
  // mean_depth_m, min_threshold_m, max_threshold_m): triangulation error
  // grows with depth, so far points get a wider band.
  double min_threshold_m = 0.002;
  // Threshold as a fraction of the landmark's mean depth.
  double relative_threshold = 0.01;
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
  // rejected; its points become outliers. Wide enough for the tilted fits
  // that a wall seen at grazing angles leaves (docs/design-notes.md).
  double ghost_max_angle_deg = 5.0;
  // See ghost_max_angle_deg.
  double ghost_distance_factor = 3.0;
  // After a segment is accepted, remaining points over its extent that lie
  // within their uncertainty band of its plane can no longer seed planes
  // (they stay outliers: unlabelled, not used for the fit). The band of a
  // point is max(its inlier threshold, covariance_sigmas x
  // tracking_noise_px x sigma_n) with sigma_n^2 = n^T C n, C =
  // Landmark::covariance_m2_per_px2: far points seen over a short baseline
  // are loose along their rays, beyond the depth-scaled threshold, and
  // would otherwise gather into tilted "ghost" planes of a real one.
  bool absorb_consistent_points = true;
  // The absorbed points also bound the segment: its polygon is redrawn over
  // its inliers and them, which brings more within reach, round after
  // round. On plain or grazing stretches of a wall the points are too loose
  // to fit the plane but still show where it extends. The inliers' own
  // outline is kept as PlaneSegment::landmark_polygon (what localization
  // renders).
  bool extend_to_absorbed = true;
  // Rounds of that extension (each reaches about one connectivity radius
  // further).
  int max_extension_rounds = 20;
  // Effective noise of a tracked position (px), drift included, scaling the
  // landmark covariance.
  double tracking_noise_px = 1.0;
  // Width of the uncertainty band in standard deviations.
  double covariance_sigmas = 3.0;
  // Polygon of a segment: false = convex hull of its inliers; true = the
  // outline of the occupancy grid of its inliers (follows concave shapes).
  bool concave_polygon = true;
  // Cell size of the occupancy grid for concave_polygon, as a factor of the
  // connectivity radius.
  double polygon_cell_factor = 0.5;
  // Count only a candidate's points over an accepted segment's polygon in
  // the ghost test, so that a surface beside a segment (a door leaf
  // recessed in its wall) is a plane of its own. Opt-in; needs
  // merge_coplanar: alone it splits walls, and with merging it was not
  // better over the whole benchmark set (docs/design-notes.md).
  bool local_ghost_test = false;
  // Give a segment the direction of the scene's well-determined planes, or
  // one at right angles to them, when its points allow it within their
  // noise (plane_directions.h): walls seen from few points at grazing
  // angles otherwise come out tilted by degrees.
  bool snap_to_directions = true;
  // Largest angle (deg) between a segment's free normal and a direction it
  // snaps to.
  double snap_max_angle_deg = 15.0;
  // A snapped plane must keep this share of the points that the free fit
  // keeps within their uncertainty band (see absorb_consistent_points).
  double snap_min_kept_fraction = 0.9;
  // A segment's normal becomes a direction for the later segments when its
  // standard error (NormalStandardErrorRad) is at most this (deg).
  double direction_max_error_deg = 0.5;
  // Merge segments of one physical plane: RANSAC's connectivity split cuts a
  // wall into pieces where its texture has gaps.
  bool merge_coplanar = true;
  // Largest angle between the normals of two segments that are merged (deg).
  double merge_max_angle_deg = 2.0;
  // Largest offset between them: each centroid, and the median of each one's
  // inliers, to the other's plane (m). Below a door's 5 cm recess.
  double merge_max_offset_m = 0.03;
  // The same offsets in units of the points' own inlier thresholds
  // (LandmarkInlierThreshold; the centroids' in their segment's median
  // threshold) must also stay within this: pieces of a far wall differ by
  // more than a near desk and the keyboard on it (about 4 thresholds).
  double merge_max_offset_thresholds = 1.5;
  // Largest gap between their polygons in the plane (m): supports that touch.
  double merge_max_gap_m = 0.3;

  void Check() const;
};

struct PlaneFittingReport {
  int num_points = 0;                  // landmarks in
  int num_planes = 0;                  // segments out
  // Of num_planes, segments added after fitting from confirmed plane
  // hypotheses (growth); the counts below include them.
  int from_hypotheses = 0;
  std::vector<int> inliers_per_plane;  // per segment, same order
  int num_outliers = 0;                // landmarks on no segment
  int iterations = 0;                  // RANSAC hypotheses drawn in total
  int rejected_hypotheses = 0;         // planes with no big enough region
  int discarded_regions = 0;           // connected regions too small to keep
  int absorbed = 0;  // outliers consistent with a segment within uncertainty
  double seconds = 0.0;                // wall-clock time
  // One merge of two segments into one plane (ids as fitted, before merging
  // renumbers the segments).
  struct Merge {
    int kept_id = 0;
    int merged_id = 0;
    double angle_deg = 0.0;  // between their normals
    double offset_m = 0.0;   // largest of the offsets tested
    // Largest of the offsets in inlier thresholds
    // (merge_max_offset_thresholds).
    double offset_thresholds = 0.0;
  };
  std::vector<Merge> merges;
  // One segment whose normal was snapped to a direction of the scene (id as
  // fitted, before merging renumbers the segments).
  struct Snap {
    int segment_id = 0;
    std::string kind;        // DirectionSnapKindName
    double angle_deg = 0.0;  // between its free and its snapped normal
    double kept_fraction = 1.0;  // DirectionSnap::kept_fraction
  };
  std::vector<Snap> snaps;
  int num_directions = 0;  // well-determined directions found
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

// Helpers FitPlanes shares with the stages that add segments
// (plane_hypotheses.h).

// Inlier threshold of a landmark (see PlaneFittingOptions::min_threshold_m).
double LandmarkInlierThreshold(const PlaneFittingOptions& options,
                               const Landmark& landmark);

// k standard deviations of a landmark along unit normal n (0 if its
// covariance is unknown).
double CovarianceBand(const Landmark& landmark, const Eigen::Vector3d& n,
                      double k);

// Flips the plane to face most of `camera_centers`; without them (null or
// empty) towards the world origin.
void OrientPlane(const std::vector<Eigen::Vector3d>* camera_centers,
                 Plane* plane);

// Frame: centroid origin, u along the principal in-plane direction. Sets
// seg->frame and seg->rms_distance_m from its points and seg->plane.
void SetSegmentFrame(const std::vector<Eigen::Vector3d>& points,
                     PlaneSegment* seg);

// RANSAC estimator of a plane from 3 points whose residual is the distance
// divided by each point's own threshold, so Ransac() runs with
// inlier_threshold = 1.
struct PlaneEstimator {
  using Model = Plane;
  static constexpr int kSampleSize = 3;
  const std::vector<Eigen::Vector3d>* points = nullptr;
  const std::vector<double>* inv_thresholds = nullptr;  // 1 / threshold_i

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
    return std::abs(model.SignedDistance((*points)[i])) * (*inv_thresholds)[i];
  }
};

}  // namespace monomap
