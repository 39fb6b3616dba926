// Direction priors for plane fitting. Indoor structure is built from a few
// directions: a floor, and walls at right angles to it and to each other
// (the "Manhattan world" of Coughlan and Yuille). A segment fitted to few or
// clustered points has a poorly determined normal: the side walls of a
// corridor, seen at grazing angles, came out 2-8 deg tilted from 33-53
// points. When the scene's well-determined directions, or a direction at
// right angles to them, explain the segment's points as well as its free
// fit does within the noise, the segment takes that direction. A plane
// whose points really tilt it (a ramp, a slanted lid) fails the test and
// keeps its own normal.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "monomap/geometry/plane.h"

namespace monomap {

struct DirectionSnapOptions {
  // Largest angle (rad) between the free normal and a direction it snaps to.
  double max_angle_rad = 0.2618;  // 15 deg
  // A point is consistent with a plane within this many of its sigmas.
  double band_sigmas = 3.0;
  // A snapped plane must keep this share of the points the free fit keeps
  // within their band.
  double min_kept_fraction = 0.9;
};

struct DirectionSnap {
  enum class Kind {
    kNone,           // the free fit is kept
    kParallel,       // normal = a known direction
    kPerpendicular,  // normal at right angles to a known direction
    kOrthogonal,     // normal = cross product of two known directions
  };
  Kind kind = Kind::kNone;
  Plane plane;             // the snapped plane, or the free fit
  double angle_deg = 0.0;  // between the free and the snapped normal
  // Points within their band of the snapped plane, over those within their
  // band of the free fit.
  double kept_fraction = 1.0;
  double weighted_rss = 0.0;  // sum of (residual / sigma)^2, snapped plane
  int dof = 0;                // normal components fixed by the snap (2, 1)
};

const char* DirectionSnapKindName(DirectionSnap::Kind kind);

// Standard error (rad) of the least-squares normal of `x` about its
// worst-determined in-plane axis: sigma / sqrt(smallest in-plane second
// moment), sigma from the residuals. Infinite for fewer than 4 points.
double NormalStandardErrorRad(const std::vector<Eigen::Vector3d>& x);

// Tries the directions derived from `directions` (unit normals of planes
// whose normal is well determined): each one, each pair's cross product,
// and the best normal at right angles to each one (weighted least squares).
// `sigmas` (m, one per point, or empty: the free fit's residual spread) are
// the points' standard deviations along the normal; a point triangulated
// over a short baseline is loose along its ray. A candidate passes when it
// is within max_angle_rad of the unweighted least-squares normal and keeps
// min_kept_fraction of the points that the free fit keeps within their
// band. This tests consistency within each point's own uncertainty, not a
// likelihood ratio: the errors of points seen from the same few frames are
// correlated through those frames' pose errors and tilt a free fit of a
// small patch by degrees, which a ratio test of independent errors reads
// as significant. Among the candidates that pass, a fully fixed normal
// (parallel, orthogonal) is preferred over a perpendicular one, then the
// smallest weighted residual. The snapped plane passes through the
// weighted centroid. Needs >= 4 points; otherwise, and when no candidate
// passes, returns the unweighted least-squares fit.
DirectionSnap SnapToDirections(const std::vector<Eigen::Vector3d>& x,
                               const std::vector<double>& sigmas,
                               const std::vector<Eigen::Vector3d>& directions,
                               const DirectionSnapOptions& options);

}  // namespace monomap
