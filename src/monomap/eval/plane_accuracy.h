// How far the textured planes of a map lie from the true surface: samples
// of each plane's seen texels (alpha != 0), and their distance to the truth
// (a ground-truth plane or the nearest point of a surface cloud).
#pragma once

#include <Eigen/Core>
#include <functional>
#include <vector>

#include "monomap/eval/point_accuracy.h"
#include "monomap/map/map.h"

namespace monomap {

struct PlaneSurfaceAccuracy {
  struct PlaneErrors {
    int id = 0;
    ErrorStats distance_m;  // over the plane's samples
  };
  std::vector<PlaneErrors> planes;  // in map order
  ErrorStats all;                   // over every sample of every plane
};

// Samples every plane's texture on a grid of `spacing_m` (at least one
// texel), skipping texels no image saw, and measures `distance(x_in_world)`
// (>= 0) at each.
PlaneSurfaceAccuracy EvaluatePlaneSurfaces(
    const Map& map, double spacing_m,
    const std::function<double(const Eigen::Vector3d&)>& distance);

}  // namespace monomap
