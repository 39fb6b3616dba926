#include "monomap/planes/see_through.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "monomap/geometry/polygon.h"
#include "monomap/planes/ray_crossing.h"
#include "monomap/util/error.h"

namespace monomap {

void SeeThroughOptions::Check() const {
  CheckOption(
      max_seen_through_ratio > 0 && std::isfinite(max_seen_through_ratio),
      "see_through.max_seen_through_ratio", "must be finite and > 0");
  CheckOption(covariance_sigmas >= 0, "see_through.covariance_sigmas",
              "must be >= 0");
  CheckOption(max_rays >= 1, "see_through.max_rays", "must be >= 1");
}

int CountSeenThrough(const SeeThroughOptions& options,
                     const PlaneFittingOptions& fitting,
                     const PlaneSegment& segment,
                     const std::vector<Rigid3d>& world_from_cam,
                     const std::vector<Landmark>& landmarks,
                     const std::vector<const Track*>& track_of_landmark) {
  const Eigen::Vector3d& n = segment.plane.normal;
  const double k = options.covariance_sigmas * fitting.tracking_noise_px;
  int count = 0;
  for (size_t i = 0; i < landmarks.size(); ++i) {
    const Landmark& l = landmarks[i];
    const Track* track = track_of_landmark[i];
    if (track == nullptr || !l.x_in_world.allFinite()) continue;
    const double s_x = segment.plane.SignedDistance(l.x_in_world);
    const double band =
        std::max(LandmarkInlierThreshold(fitting, l), CovarianceBand(l, n, k));
    if (std::abs(s_x) <= band) continue;
    bool seen = false;
    ForEachCrossingRay(segment.plane, l.x_in_world, s_x, *track, world_from_cam,
                       options.max_rays, [&](const Eigen::Vector3d& hit) {
                         seen = PointInPolygon(segment.polygon,
                                               segment.frame.ToPlane(hit));
                         return seen;
                       });
    count += seen;
  }
  return count;
}

SeeThroughReport DropSeeThroughSegments(
    const SeeThroughOptions& options, const PlaneFittingOptions& fitting,
    const std::vector<Rigid3d>& world_from_cam,
    const std::vector<Track>& tracks, std::vector<Landmark>* landmarks,
    std::vector<PlaneSegment>* segments) {
  options.Check();
  SeeThroughReport report;
  if (!options.enabled) return report;
  std::unordered_map<FeatureId, const Track*> by_id;
  for (const Track& t : tracks) by_id[t.id] = &t;
  std::vector<const Track*> track_of(landmarks->size(), nullptr);
  for (size_t i = 0; i < landmarks->size(); ++i) {
    const auto it = by_id.find((*landmarks)[i].id);
    if (it != by_id.end()) track_of[i] = it->second;
  }
  std::vector<PlaneSegment>& segs = *segments;
  report.seen_through.resize(segs.size());
  tbb::parallel_for(size_t{0}, segs.size(), [&](size_t s) {
    report.seen_through[s] = CountSeenThrough(
        options, fitting, segs[s], world_from_cam, *landmarks, track_of);
  });
  // Keep the others, renumbered in order; ids as fitted index the counts.
  std::vector<int> new_id(segs.size(), -1);
  std::vector<PlaneSegment> kept;
  for (size_t s = 0; s < segs.size(); ++s) {
    const int inliers = static_cast<int>(segs[s].inlier_ids.size());
    if (report.seen_through[s] >= options.max_seen_through_ratio * inliers) {
      report.dropped.push_back({segs[s].id, inliers, report.seen_through[s]});
      continue;
    }
    new_id[s] = static_cast<int>(kept.size());
    kept.push_back(std::move(segs[s]));
    kept.back().id = new_id[s];
  }
  for (Landmark& l : *landmarks) {
    if (l.plane_id >= 0 && l.plane_id < static_cast<int>(new_id.size())) {
      l.plane_id = new_id[l.plane_id];
    }
  }
  segs = std::move(kept);
  return report;
}

}  // namespace monomap
