// How much of the seen true structure a map's planes cover (issue 18's
// "area of the seen structure recovered"). The true planes are sampled on a
// grid; a sample is seen if some camera of the map's trajectory has it in
// its image, in front and not hidden by another true plane; it is recovered
// if a fitted plane of the same orientation passes near it and its polygon
// contains it. A seen sample is also *observable* if two of those cameras
// see it within max_incidence_deg of its plane's normal, their rays to it
// parting by at least min_parallax_deg: what any multi-view method needs to
// place it. A wall seen once, or only far ahead along the direction of
// travel, or a floor seen only at a grazing angle is seen, not observable.
#pragma once

#include <vector>

#include "monomap/geometry/rigid3.h"
#include "monomap/map/map.h"

namespace monomap {

struct AreaCoverageOptions {
  // Grid spacing (m) of the samples on each true plane.
  double sample_spacing_m = 0.05;
  // At most this many trajectory poses test visibility (evenly spread): the
  // cost grows with samples x poses x planes.
  int max_views = 60;
  // A fitted plane covers a sample within this angle (deg) of the true
  // plane's normal, the same bound as a plane match in eval structure.
  double max_angle_deg = 2.0;
  // ... and within this distance (m) of the sample.
  double max_distance_m = 0.03;
  // True planes with at least this much seen area (m^2) are "large": the
  // issue asks that 90 % of them be recovered.
  double large_plane_area_m2 = 1.0;
  // Observable: seen at most this far (deg) from the plane's normal ...
  double max_incidence_deg = 80.0;
  // ... by two views whose rays part by at least this much (deg).
  double min_parallax_deg = 2.0;

  // Throws OptionsError on a value that makes no sense.
  void Check() const;
};

// One true plane: its seen and recovered area.
struct PlaneCoverage {
  int true_id = 0;
  double seen_area_m2 = 0.0;
  double recovered_area_m2 = 0.0;
  double observable_area_m2 = 0.0;            // part of the seen area
  double recovered_observable_area_m2 = 0.0;  // part of the recovered area
};

// One map plane's area and how much of it lies on the truth: where a map
// puts area off any surface.
struct MapPlaneCoverage {
  int map_id = 0;
  double area_m2 = 0.0;
  double on_truth_m2 = 0.0;
};

struct AreaCoverage {
  double seen_area_m2 = 0.0;
  double recovered_area_m2 = 0.0;
  // recovered / seen (0 when nothing was seen).
  double area_recall = 0.0;
  // True planes with seen_area_m2 >= large_plane_area_m2, and how many of
  // them have at least half of their seen area recovered.
  int large_planes_seen = 0;
  int large_planes_recovered = 0;
  // The same over the observable samples only.
  double observable_area_m2 = 0.0;
  double recovered_observable_area_m2 = 0.0;
  double observable_recall = 0.0;
  int large_planes_observable = 0;
  int large_planes_observable_recovered = 0;
  std::vector<PlaneCoverage> planes;  // in the truth's order
  // The other direction: the map's polygons sampled on the same grid, and
  // how much of that area lies on a true plane (within the same angle and
  // distance, inside its polygon). Growing polygons over space where there
  // is no surface lowers area_precision.
  double map_area_m2 = 0.0;
  double map_area_on_truth_m2 = 0.0;
  // map_area_on_truth_m2 / map_area_m2 (0 when the map has no area).
  double area_precision = 0.0;
  std::vector<MapPlaneCoverage> map_planes;  // in the map's order
};

// Coverage of `truth`'s planes by `map`'s planes, seen from map.trajectory
// through map.camera (its pinhole model: the image bounds matter, not the
// distortion). truth_from_map takes map coordinates to truth coordinates.
// Throws OptionsError on bad options.
AreaCoverage MeasureAreaCoverage(const Map& map, const Map& truth,
                                 const Rigid3d& truth_from_map,
                                 const AreaCoverageOptions& options);

}  // namespace monomap
