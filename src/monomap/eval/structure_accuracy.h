// Accuracy of a built map against a world's exact structure (the
// simulator's true planes, DATASET/structure/ read with ReadMap): distance
// of the landmarks to the true planes, and which fitted planes match which
// true planes (normal and offset errors, plane precision and recall).
#pragma once

#include <vector>

#include "monomap/eval/area_coverage.h"
#include "monomap/eval/point_accuracy.h"
#include "monomap/geometry/rigid3.h"
#include "monomap/map/map.h"

namespace monomap {

// The map scaled by `scale` about the world origin: positions, depths,
// plane offsets and extents, texture resolution and the trajectory, so that
// a similarity alignment (eval/trajectory_metrics.h, Sim3d) can be applied
// as the scale, then the rigid part. A map takes its scale from the
// odometry, so a wheel-radius error scales the whole map.
Map ScaledMap(const Map& map, double scale);

struct StructureAccuracyOptions {
  // A fitted plane matches its true plane if the normals differ by at most
  // this angle (degrees) and the offsets by at most max_match_offset_m.
  double max_match_angle_deg = 2.0;
  // Largest offset difference (m) of a match; see max_match_angle_deg.
  double max_match_offset_m = 0.03;
  // A landmark projecting this close (m) outside a true plane's polygon
  // still counts as on it (points at corners between planes).
  double polygon_margin_m = 0.03;
  // A true plane counts as observed (for recall) if at least this many
  // landmarks lie within observed_distance_m of it.
  int min_observed_landmarks = 30;
  // Distance (m) of a landmark to its true plane to count towards
  // min_observed_landmarks.
  double observed_distance_m = 0.05;
  // How the seen area and the area the planes recover are measured.
  AreaCoverageOptions coverage;

  // Throws OptionsError on a value that makes no sense.
  void Check() const;
};

// One fitted plane compared with the ground truth.
struct PlaneMatch {
  int fitted_id = 0;
  // Landmarks labelled with this plane.
  int inliers = 0;
  // Id of the true plane most of its inliers lie on; if none lies on the
  // structure, the true plane closest in angle and offset (-1 only if the
  // truth has no plane).
  int true_id = -1;
  double normal_error_deg = 0.0;
  double offset_error_m = 0.0;
  // Within max_match_angle_deg and max_match_offset_m.
  bool matched = false;
};

// One true plane and how the map found it.
struct TruePlaneResult {
  int true_id = 0;
  // Landmarks assigned to it within observed_distance_m.
  int near_landmarks = 0;
  // near_landmarks >= min_observed_landmarks: recall counts it.
  bool observed = false;
  // Some fitted plane matches it.
  bool matched = false;
  // Its best fitted plane among those compared with it (a matching one
  // first, then the smallest normal error); -1 if no fitted plane was
  // compared with it (the errors are then meaningless, 0).
  int best_fitted_id = -1;
  double normal_error_deg = 0.0;
  double offset_error_m = 0.0;
};

struct StructureAccuracy {
  int true_planes = 0;
  // True planes with enough landmarks on them to be found.
  int observed_true_planes = 0;
  int fitted_planes = 0;
  int landmarks = 0;

  // Landmark distance to the nearest true plane containing its projection
  // (absolute, and % of the landmark's mean depth). All landmarks, and
  // only those the map put on a plane.
  PointAccuracy point_error_all;
  PointAccuracy point_error_on_planes;
  // Landmarks whose projection lies on no true plane (not evaluated).
  int landmarks_off_structure = 0;

  // One per fitted plane, in the map's order.
  std::vector<PlaneMatch> matches;
  // Over the fitted planes compared with a true plane.
  ErrorStats normal_error_deg;
  ErrorStats offset_error_m;
  // Matched fitted planes / fitted planes (0 without fitted planes).
  double precision = 0.0;
  // Observed true planes matched by some fitted plane / observed true
  // planes (0 without observed true planes).
  double recall = 0.0;

  // One per true plane, in the truth's order.
  std::vector<TruePlaneResult> true_plane_results;
  // Seen and recovered area of the true planes (coverage.planes is in the
  // truth's order too).
  AreaCoverage coverage;
};

// Compares `map` (map.planes and the landmarks' plane_id) with the true
// structure `truth` (its planes with their polygons; textures unused).
// truth_from_map takes map coordinates to truth coordinates. Each landmark
// is assigned to the nearest true plane whose polygon (grown by
// polygon_margin_m) contains its projection; each fitted plane is compared
// with the true plane most of its inliers are assigned to (coplanar true
// planes are told apart by extent). Throws OptionsError on bad options.
StructureAccuracy EvaluateStructure(const Map& map, const Map& truth,
                                    const Rigid3d& truth_from_map,
                                    const StructureAccuracyOptions& options);

// Landmarks read back from a map directory carry no mean depth (points.ply
// does not store it), and the relative point errors divide by it. Sets
// every landmark's mean_depth_m as the triangulation defines it: the mean
// distance from the camera centres (map->trajectory, indexed by frame) of
// its track's observations (the map's features.csv, see
// io/feature_table.h). A landmark without a track, or with an observation
// outside the trajectory, gets the distance to the nearest camera centre
// instead (0 without a trajectory). Returns how many landmarks took the
// track definition.
int SetLandmarkDepths(const std::vector<Track>& tracks, Map* map);

}  // namespace monomap
