// The export's trust filter: which triangulated points the map writes to
// points.ply. Triangulation already refuses points it cannot compute; this
// stage leaves out, at export, the ones it computed but does not trust (few
// observations, a large residual after bundle adjustment, rays too close to
// parallel to fix the depth, a position its own covariance says is loose),
// judged on the quality each Landmark carries.
#pragma once

#include <vector>

#include "monomap/map/map.h"

namespace monomap {

struct PointTrustOptions {
  // Fewest observations (Landmark::num_observations) of an exported point:
  // the one threshold that helped every run of the generalization set.
  int min_track_length = 6;
  // Largest mean reprojection error (raw px, after bundle adjustment); as
  // triangulation's own limit, since tighter made some runs worse.
  double max_mean_reprojection_error_px = 2.0;
  // ... and at most this many times the median of all the points' mean
  // reprojection errors (0: off): the image noise differs between cameras,
  // so a limit relative to the map's own noise fits every camera; the
  // largest ratio of those tried that was no worse anywhere in the
  // generalization set.
  double max_reprojection_error_median_ratio = 3.0;
  // Smallest largest angle between observing rays (degrees); as
  // triangulation's own limit, for the same reason.
  double min_triangulation_angle_deg = 1.5;
  // Largest predicted standard deviation of a point along its loosest
  // direction, at 1 px of tracking noise (the square root of the largest
  // eigenvalue of Landmark::covariance_m2_per_px2), as a fraction of its
  // mean depth. Depth, baseline and viewing geometry together, where the
  // angle test sees the angle alone. <= 0: off. Points without a covariance
  // pass.
  double max_relative_uncertainty = 0.02;
  // Export every point; the report still counts the untrusted ones.
  bool keep_all = false;
  // Throws OptionsError naming the field if a value makes no sense.
  void Check() const;
};

struct PointTrustReport {
  int num_points = 0;    // landmarks given
  int num_exported = 0;  // landmarks kept
  // The mean reprojection error limit applied (px): the absolute one, or
  // the median ratio's when smaller.
  double reprojection_limit_px = 0.0;
  // Untrusted points, each counted once under the first test it fails in
  // this order; left out unless keep_all.
  int short_track = 0;
  int reprojection_error = 0;
  int triangulation_angle = 0;
  int uncertainty = 0;
  bool keep_all = false;
};

// Keeps, in order, the landmarks that pass every test of `options` (all of
// them with keep_all) and counts the others by reason.
PointTrustReport FilterTrustedPoints(const PointTrustOptions& options,
                                     std::vector<Landmark>* landmarks);

}  // namespace monomap
