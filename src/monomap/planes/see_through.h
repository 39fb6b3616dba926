// Free-space check of fitted planes: an opaque surface hides what lies
// behind it. A segment through whose polygon the cameras saw more landmarks
// lying beyond it than it has inliers of its own is no surface. On a wall
// seen at grazing angles, features that drift as the wall foreshortens
// triangulate into a layer a few centimetres in front of it; plane fitting
// cannot tell that layer from a real one (a poster, a door frame), but the
// wall's own points, seen through it, can.
#pragma once

#include <vector>

#include "monomap/geometry/rigid3.h"
#include "monomap/map/map.h"
#include "monomap/planes/plane_fitting.h"

namespace monomap {

struct SeeThroughOptions {
  // Off: segments are kept as fitted.
  bool enabled = true;
  // A segment is dropped when the landmarks seen through its polygon number
  // at least this many times its inliers.
  double max_seen_through_ratio = 1.0;
  // A landmark counts when it lies beyond the plane by more than its band:
  // its plane-fitting inlier threshold, or this many sigmas of its
  // covariance along the normal (at PlaneFittingOptions::tracking_noise_px)
  // if wider.
  double covariance_sigmas = 3.0;
  // Observations per landmark whose rays are tested (evenly spread over its
  // track).
  int max_rays = 5;
  // Throws OptionsError naming the field if a value makes no sense.
  void Check() const;
};

struct SeeThroughReport {
  // Per segment as fitted: landmarks seen through its polygon.
  std::vector<int> seen_through;
  // One dropped segment (id as fitted).
  struct Dropped {
    int segment_id = 0;
    int inliers = 0;
    int seen_through = 0;
  };
  std::vector<Dropped> dropped;
};

// Landmarks that some observing camera (`tracks` give the frames,
// `world_from_cam` the poses) saw through `segment`'s polygon while they lie
// beyond its plane by more than their band.
int CountSeenThrough(const SeeThroughOptions& options,
                     const PlaneFittingOptions& fitting,
                     const PlaneSegment& segment,
                     const std::vector<Rigid3d>& world_from_cam,
                     const std::vector<Landmark>& landmarks,
                     const std::vector<const Track*>& track_of_landmark);

// Drops the segments that fail the check, renumbers the others (ids 0..n-1
// in their order) and their landmarks' plane_id; the dropped segments'
// inliers get plane_id -1. `tracks` are matched to landmarks by id.
SeeThroughReport DropSeeThroughSegments(
    const SeeThroughOptions& options, const PlaneFittingOptions& fitting,
    const std::vector<Rigid3d>& world_from_cam,
    const std::vector<Track>& tracks, std::vector<Landmark>* landmarks,
    std::vector<PlaneSegment>* segments);

}  // namespace monomap
