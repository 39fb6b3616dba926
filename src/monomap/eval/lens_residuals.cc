#include "monomap/eval/lens_residuals.h"

#include <algorithm>
#include <cmath>

#include "monomap/eval/point_accuracy.h"
#include "monomap/geometry/triangulation.h"
#include "monomap/triangulation/triangulator.h"
#include "monomap/util/error.h"

namespace monomap {

void LensResidualOptions::Check() const {
  CheckOption(centre_radius_px > 0.0, "centre_radius_px", "must be > 0");
  CheckOption(ring_px > 0.0, "ring_px", "must be > 0");
  CheckOption(min_centre_observations >= 2, "min_centre_observations",
              "must be >= 2");
  CheckOption(max_centre_median_px > 0.0, "max_centre_median_px",
              "must be > 0");
}

namespace {

bool InRange(const Observation& o, const std::vector<Rigid3d>& cams) {
  return o.frame >= 0 && o.frame < static_cast<int>(cams.size());
}

// The track's point triangulated from its observations near the principal
// point only (where the lens model matters least); false when too few, behind
// a camera, or not consistent enough there.
bool TriangulateFromCentre(const Camera& camera,
                           const std::vector<Rigid3d>& cams_from_world,
                           const Track& track,
                           const LensResidualOptions& options,
                           Eigen::Vector3d* x) {
  const Eigen::Vector2d centre(camera.cx, camera.cy);
  Track central;
  central.id = track.id;
  std::vector<Rigid3d> cams;
  std::vector<Eigen::Vector2d> normalized;
  for (const Observation& o : track.observations) {
    if (!InRange(o, cams_from_world)) continue;
    if ((o.px - centre).norm() > options.centre_radius_px) continue;
    central.observations.push_back(o);
    cams.push_back(cams_from_world[o.frame]);
    normalized.push_back(camera.NormalizedFromImage(o.px));
  }
  if (static_cast<int>(central.observations.size()) <
      options.min_centre_observations) {
    return false;
  }
  if (!TriangulateLinear(cams, normalized, x)) return false;
  RefinePoint(camera, cams_from_world, central, TriangulationOptions(), x);
  std::vector<double> centre_errors;
  bool in_front = true;
  for (const Observation& o : central.observations) {
    const Eigen::Vector3d x_in_cam = cams_from_world[o.frame] * *x;
    in_front = in_front && x_in_cam.z() > 0.0;
    if (in_front) {
      centre_errors.push_back((camera.ImageFromCam(x_in_cam) - o.px).norm());
    }
  }
  if (!in_front ||
      ComputeErrorStats(centre_errors).median > options.max_centre_median_px) {
    return false;
  }
  return true;
}

// The rings' statistics of the radial and tangential residuals.
std::vector<LensResidualRing> SummarizeRings(
    const std::vector<std::vector<double>>& radial,
    const std::vector<std::vector<double>>& tangential, double ring_px) {
  std::vector<LensResidualRing> rings;
  for (size_t k = 0; k < radial.size(); ++k) {
    if (radial[k].empty()) continue;
    LensResidualRing ring;
    ring.min_radius_px = k * ring_px;
    ring.max_radius_px = (k + 1) * ring_px;
    ring.count = static_cast<int>(radial[k].size());
    const ErrorStats radial_stats = ComputeErrorStats(radial[k]);
    ring.radial_mean_px = radial_stats.mean;
    ring.radial_median_px = radial_stats.median;
    ring.tangential_median_px = ComputeErrorStats(tangential[k]).median;
    rings.push_back(ring);
  }
  return rings;
}

}  // namespace

LensResidualReport EvaluateLensResiduals(
    const Camera& camera, const std::vector<Rigid3d>& world_from_cam,
    const std::vector<Track>& tracks, const LensResidualOptions& options) {
  options.Check();
  std::vector<Rigid3d> cams_from_world;
  for (const Rigid3d& p : world_from_cam)
    cams_from_world.push_back(p.Inverse());
  const Eigen::Vector2d centre(camera.cx, camera.cy);
  const double max_radius =
      std::hypot(std::max(camera.cx, camera.width - camera.cx),
                 std::max(camera.cy, camera.height - camera.cy));
  const int num_rings =
      static_cast<int>(std::ceil(max_radius / options.ring_px));
  std::vector<std::vector<double>> radial(num_rings), tangential(num_rings);
  LensResidualReport report;
  for (const Track& track : tracks) {
    Eigen::Vector3d x;
    if (!TriangulateFromCentre(camera, cams_from_world, track, options, &x)) {
      continue;
    }
    ++report.tracks_used;
    for (const Observation& o : track.observations) {
      if (!InRange(o, cams_from_world)) continue;
      const Eigen::Vector3d x_in_cam = cams_from_world[o.frame] * x;
      if (x_in_cam.z() <= 0.0) continue;
      const Eigen::Vector2d d = o.px - camera.ImageFromCam(x_in_cam);
      const Eigen::Vector2d outward = o.px - centre;
      const double r = outward.norm();
      if (r < 1e-9) continue;
      const Eigen::Vector2d u = outward / r;
      const int ring =
          std::min(num_rings - 1, static_cast<int>(r / options.ring_px));
      radial[ring].push_back(d.dot(u));
      tangential[ring].push_back(u.x() * d.y() - u.y() * d.x());
    }
  }
  report.rings = SummarizeRings(radial, tangential, options.ring_px);
  return report;
}

}  // namespace monomap
