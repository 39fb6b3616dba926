// Plane inliers placed on their plane as the map measures it locally
// (issue 18, item 3). A point seen at a few degrees of parallax carries
// centimetres of depth noise, while its neighbours on the same wall,
// each with its own independent noise, tell where the wall is. Each
// inlier moves to the median offset of its nearest fellow inliers: a
// local estimate, so that a map bent by pose error keeps its bend (one
// global plane would move points the map measures well), and a median, so
// that a few stray inliers do not shift it. The point moves along its own
// loosest direction (Gaussian conditioning on its covariance: mostly along
// its rays), so its image positions change as little as the move allows.
#pragma once

#include <vector>

#include "monomap/map/map.h"

namespace monomap {

struct InlierRefinementOptions {
  // Move plane inliers at all (off: the export keeps the triangulated
  // positions).
  bool enabled = true;
  // Inliers of the same plane (itself included) whose median signed
  // distance to the plane is a point's local offset: enough to average
  // the points' independent noise, few enough to follow the map's bending.
  int neighbours = 50;
  // Throws OptionsError naming the field if a value makes no sense.
  void Check() const;
};

struct InlierRefinementReport {
  bool enabled = false;
  int num_moved = 0;  // inliers moved (those whose plane is a segment)
  // Distance each moved point travelled (m): median and largest.
  double median_move_m = 0.0;
  double max_move_m = 0.0;
  // Median |signed distance to the local offset| before the move, as a
  // fraction of the point's mean depth: the noise the move removed.
  double median_relative_offset = 0.0;
};

// Moves every landmark whose plane_id names one of `segments` to its local
// offset on that plane (neighbours among the landmarks given, so among
// the exported ones when called after the trust filter).
InlierRefinementReport RefineInliersOnPlanes(
    const InlierRefinementOptions& options,
    const std::vector<PlaneSegment>& segments,
    std::vector<Landmark>* landmarks);

}  // namespace monomap
