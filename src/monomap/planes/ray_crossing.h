// Free-space evidence shared by the see-through check (see_through.h) and
// plane growth's carving (plane_growth.h): a landmark seen by a camera on
// the other side of a plane lies behind it, and the ray between them
// crosses the plane at a point that cannot be opaque.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <vector>

#include "monomap/geometry/plane.h"
#include "monomap/geometry/rigid3.h"
#include "monomap/map/map.h"

namespace monomap {

// For up to max_rays of `track`'s observations, spread evenly over it, whose
// camera centre lies on the other side of `plane` than x (s_x: x's signed
// distance), calls on_hit with the point where the ray from that centre to x
// crosses the plane. Stops early when on_hit returns true. Observations of
// frames without a pose are skipped.
template <typename OnHit>
void ForEachCrossingRay(const Plane& plane, const Eigen::Vector3d& x,
                        double s_x, const Track& track,
                        const std::vector<Rigid3d>& world_from_cam,
                        int max_rays, OnHit&& on_hit) {
  const std::vector<Observation>& obs = track.observations;
  const int m = static_cast<int>(obs.size());
  const int rays = std::min(m, max_rays);
  for (int r = 0; r < rays; ++r) {
    const int f = obs[rays > 1 ? r * (m - 1) / (rays - 1) : 0].frame;
    if (f < 0 || f >= static_cast<int>(world_from_cam.size())) continue;
    const Eigen::Vector3d& c = world_from_cam[f].translation;
    const double s_c = plane.SignedDistance(c);
    if (s_c * s_x >= 0) continue;  // on the camera's side: not behind
    if (on_hit(Eigen::Vector3d(c + s_c / (s_c - s_x) * (x - c)))) return;
  }
}

}  // namespace monomap
