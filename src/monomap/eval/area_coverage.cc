#include "monomap/eval/area_coverage.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "monomap/geometry/polygon.h"
#include "monomap/util/angles.h"
#include "monomap/util/error.h"

namespace monomap {

void AreaCoverageOptions::Check() const {
  CheckOption(sample_spacing_m > 0 && std::isfinite(sample_spacing_m),
              "coverage.sample_spacing_m", "must be positive");
  CheckOption(max_views >= 1, "coverage.max_views", "must be at least 1");
  CheckOption(max_angle_deg > 0 && max_angle_deg < 90,
              "coverage.max_angle_deg", "must be in (0, 90)");
  CheckOption(max_distance_m > 0 && std::isfinite(max_distance_m),
              "coverage.max_distance_m", "must be positive");
  CheckOption(large_plane_area_m2 >= 0 && std::isfinite(large_plane_area_m2),
              "coverage.large_plane_area_m2", "must not be negative");
  CheckOption(max_incidence_deg > 0 && max_incidence_deg <= 90,
              "coverage.max_incidence_deg", "must be in (0, 90]");
  CheckOption(min_parallax_deg >= 0 && min_parallax_deg < 180,
              "coverage.min_parallax_deg", "must be in [0, 180)");
}

namespace {

// Grid samples (cell centres, spacing h) inside a plane's polygon, in the
// truth's world frame.
std::vector<Eigen::Vector3d> SamplePlane(const TexturedPlane& p, double h) {
  std::vector<Eigen::Vector3d> out;
  if (p.polygon.size() < 3) return out;  // unbounded: no area to count
  Eigen::Vector2d lo = p.polygon[0], hi = p.polygon[0];
  for (const auto& v : p.polygon) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  for (double s = lo.x() + 0.5 * h; s < hi.x(); s += h) {
    for (double t = lo.y() + 0.5 * h; t < hi.y(); t += h) {
      if (PointInPolygon(p.polygon, {s, t})) out.push_back(p.frame.ToWorld({s, t}));
    }
  }
  return out;
}

// Whether the segment from the camera centre c to x crosses a true plane
// other than `self` inside its polygon before reaching x.
bool Occluded(const std::vector<TexturedPlane>& truth, size_t self,
              const Eigen::Vector3d& c, const Eigen::Vector3d& x) {
  const Eigen::Vector3d d = x - c;
  for (size_t k = 0; k < truth.size(); ++k) {
    if (k == self) continue;
    const Plane& pl = truth[k].plane;
    const double denom = pl.normal.dot(d);
    if (std::abs(denom) < 1e-12) continue;
    const double t = -pl.SignedDistance(c) / denom;
    // Stop short of x: planes meeting at x's edge do not hide it.
    if (t <= 1e-6 || t >= 1.0 - 1e-3) continue;
    const TexturedPlane& q = truth[k];
    if (q.polygon.size() < 3 || PointInPolygon(q.polygon, q.frame.ToPlane(c + t * d))) {
      return true;
    }
  }
  return false;
}

// A camera that tests visibility: its pose and centre in the truth's frame.
struct View {
  Rigid3d cam_from_truth;
  Eigen::Vector3d center_in_truth;
};

// How a sample is seen (see AreaCoverageOptions).
struct Visibility {
  bool seen = false;
  bool observable = false;
};

Visibility Visible(const Camera& camera, const std::vector<View>& views,
                   const std::vector<TexturedPlane>& truth, size_t self,
                   const Eigen::Vector3d& x, const AreaCoverageOptions& o) {
  const double cos_incidence = std::cos(DegToRad(o.max_incidence_deg));
  const double cos_parallax = std::cos(DegToRad(o.min_parallax_deg));
  const Eigen::Vector3d& normal = truth[self].plane.normal;
  Visibility v;
  std::vector<Eigen::Vector3d> rays;  // of the views within the incidence
  for (const View& view : views) {
    const Eigen::Vector3d x_in_cam = view.cam_from_truth * x;
    if (x_in_cam.z() <= 1e-3) continue;
    const Eigen::Vector2d xn = x_in_cam.head<2>() / x_in_cam.z();
    if (!camera.InImage(camera.PinholeFromNormalized(xn))) continue;
    if (Occluded(truth, self, view.center_in_truth, x)) continue;
    v.seen = true;
    const Eigen::Vector3d ray = (x - view.center_in_truth).normalized();
    if (std::abs(ray.dot(normal)) < cos_incidence) continue;
    for (const Eigen::Vector3d& r : rays) {
      if (r.dot(ray) <= cos_parallax) {
        v.observable = true;
        return v;
      }
    }
    rays.push_back(ray);
  }
  return v;
}

// Whether a fitted plane (map frame) of about the same orientation as the
// true normal passes near x_in_map and its polygon contains x_in_map.
bool Recovered(const Map& map, const Eigen::Vector3d& normal_in_map,
               const Eigen::Vector3d& x_in_map,
               const AreaCoverageOptions& o) {
  const double cos_max = std::cos(DegToRad(o.max_angle_deg));
  for (const TexturedPlane& p : map.planes) {
    if (std::abs(p.plane.normal.dot(normal_in_map)) < cos_max) continue;
    if (std::abs(p.plane.SignedDistance(x_in_map)) > o.max_distance_m) continue;
    if (PointInPolygon(p.polygon, p.frame.ToPlane(x_in_map))) return true;
  }
  return false;
}

// At most max_views poses of the trajectory, evenly spread.
std::vector<View> Views(const Map& map, const Rigid3d& truth_from_map,
                        int max_views) {
  std::vector<View> views;
  const size_t n = map.trajectory.size();
  const size_t step = std::max<size_t>(1, (n + max_views - 1) / max_views);
  for (size_t i = 0; i < n; i += step) {
    const Rigid3d truth_from_cam =
        truth_from_map * map.trajectory[i].world_from_cam;
    views.push_back({truth_from_cam.Inverse(), truth_from_cam.translation});
  }
  return views;
}

PlaneCoverage CoverPlane(const Map& map, const Map& truth, size_t j,
                         const Rigid3d& truth_from_map,
                         const std::vector<View>& views,
                         const AreaCoverageOptions& o) {
  const TexturedPlane& p = truth.planes[j];
  const std::vector<Eigen::Vector3d> samples = SamplePlane(p, o.sample_spacing_m);
  const Rigid3d map_from_truth = truth_from_map.Inverse();
  const Eigen::Vector3d normal_in_map = map_from_truth.rotation * p.plane.normal;
  int seen = 0, recovered = 0, observable = 0, recovered_observable = 0;
  for (const Eigen::Vector3d& x : samples) {
    const Visibility v = Visible(map.camera, views, truth.planes, j, x, o);
    if (!v.seen) continue;
    ++seen;
    const bool r = Recovered(map, normal_in_map, map_from_truth * x, o);
    recovered += r ? 1 : 0;
    observable += v.observable ? 1 : 0;
    recovered_observable += v.observable && r ? 1 : 0;
  }
  const double cell = o.sample_spacing_m * o.sample_spacing_m;
  return {p.id, seen * cell, recovered * cell, observable * cell,
          recovered_observable * cell};
}

// Area of map plane `p` (samples of spacing h) and how much of it lies on
// a true plane of the same orientation, within max_distance_m, inside its
// polygon.
void MapPlaneOnTruth(const TexturedPlane& p, const Map& truth,
                     const Rigid3d& truth_from_map, const AreaCoverageOptions& o,
                     double* area_m2, double* on_truth_m2) {
  const double cos_max = std::cos(DegToRad(o.max_angle_deg));
  const Eigen::Vector3d normal_in_truth = truth_from_map.rotation * p.plane.normal;
  const std::vector<Eigen::Vector3d> samples = SamplePlane(p, o.sample_spacing_m);
  int on = 0;
  for (const Eigen::Vector3d& x_in_map : samples) {
    const Eigen::Vector3d x = truth_from_map * x_in_map;
    for (const TexturedPlane& q : truth.planes) {
      if (std::abs(q.plane.normal.dot(normal_in_truth)) < cos_max) continue;
      if (std::abs(q.plane.SignedDistance(x)) > o.max_distance_m) continue;
      if (q.polygon.size() >= 3 && !PointInPolygon(q.polygon, q.frame.ToPlane(x))) {
        continue;
      }
      ++on;
      break;
    }
  }
  const double cell = o.sample_spacing_m * o.sample_spacing_m;
  *area_m2 = samples.size() * cell;
  *on_truth_m2 = on * cell;
}

// A plane with at least large_plane_area_m2 of `area` is large; it is
// recovered when at least half of that area is.
void CountLargePlane(double area, double recovered,
                     const AreaCoverageOptions& o, int* large,
                     int* large_recovered) {
  if (area < o.large_plane_area_m2 || area <= 0) return;
  ++*large;
  if (recovered >= 0.5 * area) ++*large_recovered;
}

}  // namespace

AreaCoverage MeasureAreaCoverage(const Map& map, const Map& truth,
                                 const Rigid3d& truth_from_map,
                                 const AreaCoverageOptions& options) {
  options.Check();
  const std::vector<View> views =
      Views(map, truth_from_map, options.max_views);
  AreaCoverage result;
  result.planes.resize(truth.planes.size());
  tbb::parallel_for(size_t{0}, truth.planes.size(), [&](size_t j) {
    result.planes[j] = CoverPlane(map, truth, j, truth_from_map, views, options);
  });
  for (const PlaneCoverage& c : result.planes) {
    result.seen_area_m2 += c.seen_area_m2;
    result.recovered_area_m2 += c.recovered_area_m2;
    result.observable_area_m2 += c.observable_area_m2;
    result.recovered_observable_area_m2 += c.recovered_observable_area_m2;
    CountLargePlane(c.seen_area_m2, c.recovered_area_m2, options,
                    &result.large_planes_seen, &result.large_planes_recovered);
    CountLargePlane(c.observable_area_m2, c.recovered_observable_area_m2,
                    options, &result.large_planes_observable,
                    &result.large_planes_observable_recovered);
  }
  if (result.seen_area_m2 > 0) {
    result.area_recall = result.recovered_area_m2 / result.seen_area_m2;
  }
  if (result.observable_area_m2 > 0) {
    result.observable_recall =
        result.recovered_observable_area_m2 / result.observable_area_m2;
  }
  for (const TexturedPlane& p : map.planes) {
    double area = 0.0, on = 0.0;
    MapPlaneOnTruth(p, truth, truth_from_map, options, &area, &on);
    result.map_area_m2 += area;
    result.map_area_on_truth_m2 += on;
    result.map_planes.push_back({p.id, area, on});
  }
  if (result.map_area_m2 > 0) {
    result.area_precision = result.map_area_on_truth_m2 / result.map_area_m2;
  }
  return result;
}

}  // namespace monomap
