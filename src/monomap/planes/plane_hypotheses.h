// Plane hypotheses where too few landmarks lie for RANSAC (issue 18, item
// 1). An end wall seen head-on down a corridor, a door leaf, a wall of plain
// paint: a handful of landmarks each, below FitPlanes' min_inliers. Indoor
// structure has few directions, and the planes already found give them (a
// floor, walls, and the directions at right angles to two of them). Along
// a known direction a plane has a single unknown, its offset, so a few
// landmarks at one offset are a hypothesis. They are proposals only: plane
// growth keeps a hypothesis only where the images confirm it through its
// plane-induced homographies (GrowPlanePolygons).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "monomap/map/map.h"
#include "monomap/planes/plane_fitting.h"

namespace monomap {

struct PlaneHypothesisOptions {
  // Propose hypotheses at all; they are checked by plane growth, so they
  // take effect only when it is enabled. Opt-in: a few loose points can
  // confirm a wrong wall through a wide lens (docs/design-notes.md).
  bool enabled = false;
  // Landmarks on no segment that a hypothesis needs (three fix a free
  // plane; a known direction leaves one unknown, and the rest guard
  // against chance alignments of clutter).
  int min_points = 5;
  // Segment normals within this angle (deg) are one direction.
  double same_direction_deg = 5.0;
  // Cross products of two directions at least this far apart (deg) are
  // directions too (the end wall of a corridor: floor x side wall).
  double min_cross_angle_deg = 30.0;
  // Two landmarks are neighbours in one hypothesis if their in-plane
  // distance is below this fraction of their mean depth (scale-free: a
  // desk and a hallway see the same image spacing).
  double neighbour_depth_fraction = 0.25;
  // A landmark within its uncertainty band of a segment and within this
  // fraction of its depth of that segment's polygon belongs to it, not to
  // a hypothesis (FitPlanes' absorbed points).
  double near_segment_depth_fraction = 0.1;
  // A hypothesis parallel to a segment (normals within this angle, deg)
  // and within the band of its points of that segment's plane is that
  // segment again, beyond its polygon: growth, not a new plane, extends it.
  double coplanar_max_angle_deg = 2.0;
  // ... the band widened by this many standard errors of the segment's
  // normal times the hypothesis' distance from its polygon (a fitted plane
  // drifts off its wall with the distance from its points).
  double normal_error_sigmas = 3.0;
  // Most hypotheses proposed.
  int max_hypotheses = 20;

  void Check() const;
};

// Proposes planes along the scene's directions through the landmarks on no
// segment (plane_id < 0), best supported first. Each is a PlaneSegment
// with ids after those of `segments`, its landmarks as inliers (their
// plane_id is not changed), a frame and the convex hull of its inliers as
// polygon, facing the cameras. `fitting` gives the landmarks' uncertainty
// bands. Throws OptionsError for bad options.
std::vector<PlaneSegment> ProposePlaneHypotheses(
    const PlaneHypothesisOptions& options, const PlaneFittingOptions& fitting,
    const std::vector<Landmark>& landmarks,
    const std::vector<PlaneSegment>& segments,
    const std::vector<Eigen::Vector3d>& camera_centers);

// The unit directions of the segments' normals, merged within
// same_direction_deg, then their pairwise cross products (for pairs at
// least min_cross_angle_deg apart) not already among them.
std::vector<Eigen::Vector3d> SceneDirections(
    const PlaneHypothesisOptions& options,
    const std::vector<PlaneSegment>& segments);

}  // namespace monomap
