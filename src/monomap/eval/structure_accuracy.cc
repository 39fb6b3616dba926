#include "monomap/eval/structure_accuracy.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

#include "monomap/geometry/polygon.h"
#include "monomap/util/angles.h"
#include "monomap/util/error.h"

namespace monomap {

void StructureAccuracyOptions::Check() const {
  CheckOption(max_match_angle_deg > 0 && std::isfinite(max_match_angle_deg),
              "structure.max_match_angle_deg", "must be positive");
  CheckOption(max_match_offset_m > 0 && std::isfinite(max_match_offset_m),
              "structure.max_match_offset_m", "must be positive");
  CheckOption(polygon_margin_m >= 0 && std::isfinite(polygon_margin_m),
              "structure.polygon_margin_m", "must not be negative");
  CheckOption(min_observed_landmarks >= 1, "structure.min_observed_landmarks",
              "must be at least 1");
  CheckOption(observed_distance_m > 0 && std::isfinite(observed_distance_m),
              "structure.observed_distance_m", "must be positive");
  coverage.Check();
}

Map ScaledMap(const Map& map, double scale) {
  Map out = map;
  for (Landmark& l : out.landmarks) {
    l.x_in_world *= scale;
    l.mean_depth_m *= scale;
    l.covariance_m2_per_px2 *= scale * scale;
  }
  for (TexturedPlane& p : out.planes) {
    p.plane.offset *= scale;
    p.frame.origin *= scale;
    p.pixels_per_meter /= scale;
    for (Eigen::Vector2d& v : p.polygon) v *= scale;
    for (Eigen::Vector2d& v : p.landmark_polygon) v *= scale;
    for (PlaneFeature& f : p.features) f.x_in_world *= scale;
  }
  for (TimedPose& t : out.trajectory) {
    t.world_from_cam.translation *= scale;
  }
  return out;
}

namespace {

// A landmark's nearest true plane among those containing its projection.
struct Assignment {
  int true_index = -1;
  double distance_m = 0.0;
};

Assignment AssignToTruth(const std::vector<TexturedPlane>& truth,
                         const Eigen::Vector3d& x, double margin_m) {
  Assignment best;
  best.distance_m = std::numeric_limits<double>::infinity();
  for (size_t j = 0; j < truth.size(); ++j) {
    const TexturedPlane& p = truth[j];
    const double d = std::abs(p.plane.SignedDistance(x));
    if (d >= best.distance_m) continue;
    const Eigen::Vector2d st = p.frame.ToPlane(x);
    // A polygon of fewer than 3 vertices bounds nothing: the whole plane.
    const bool inside =
        p.polygon.size() < 3 || DistanceToPolygon(p.polygon, st) <= margin_m;
    if (inside) best = {static_cast<int>(j), d};
  }
  if (best.true_index < 0) best.distance_m = 0.0;
  return best;
}

// A fitted plane and the centre of its extent, in the truth's frame.
struct FittedPlane {
  Plane plane;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
};

// The centre is the centroid of the polygon (the frame's origin without
// one), projected on the plane in case the frame is off it.
FittedPlane FittedInTruth(const TexturedPlane& fitted,
                          const Rigid3d& truth_from_map) {
  const Eigen::Vector3d c =
      fitted.frame.ToWorld(PolygonCentroid(fitted.polygon));
  return {fitted.plane.Transformed(truth_from_map),
          truth_from_map * fitted.plane.Project(c)};
}

// Angle between the normals (orientation ignored), and the offset: the
// distance of the fitted plane's centre to the true plane. Measured where
// the plane is, not as the difference of the offsets at the world origin,
// which grows with the plane's distance from the origin: a wall 8 m away
// tilted by 0.4 deg differs there by 5.6 cm.
void ComparePlanes(const FittedPlane& fitted, const Plane& truth,
                   double* angle_deg, double* offset_m) {
  const double cos_angle = std::abs(fitted.plane.normal.dot(truth.normal));
  *angle_deg = RadToDeg(std::acos(std::clamp(cos_angle, -1.0, 1.0)));
  *offset_m = std::abs(truth.SignedDistance(fitted.center));
}

// Assigns every landmark to its true plane (`assignment`), counts the
// landmarks near each true plane (`near_count`) and fills the point errors.
void ScorePoints(const Map& map, const Map& truth,
                 const Rigid3d& truth_from_map,
                 const StructureAccuracyOptions& options,
                 std::vector<Assignment>* assignment,
                 std::vector<int>* near_count, StructureAccuracy* result) {
  assignment->assign(map.landmarks.size(), Assignment());
  near_count->assign(truth.planes.size(), 0);
  std::vector<double> abs_all, rel_all, abs_on, rel_on;
  for (size_t i = 0; i < map.landmarks.size(); ++i) {
    const Landmark& l = map.landmarks[i];
    const Eigen::Vector3d x = truth_from_map * l.x_in_world;
    (*assignment)[i] = AssignToTruth(truth.planes, x, options.polygon_margin_m);
    const Assignment& a = (*assignment)[i];
    if (a.true_index < 0) {
      ++result->landmarks_off_structure;
      continue;
    }
    if (a.distance_m <= options.observed_distance_m) {
      ++(*near_count)[a.true_index];
    }
    const double rel =
        l.mean_depth_m > 0 ? a.distance_m / l.mean_depth_m * 100.0 : 0.0;
    abs_all.push_back(a.distance_m);
    rel_all.push_back(rel);
    if (l.plane_id >= 0) {
      abs_on.push_back(a.distance_m);
      rel_on.push_back(rel);
    }
  }
  result->point_error_all = {ComputeErrorStats(abs_all),
                             ComputeErrorStats(rel_all),
                             ShareAbove(abs_all, 0.01)};
  result->point_error_on_planes = {ComputeErrorStats(abs_on),
                                   ComputeErrorStats(rel_on),
                                   ShareAbove(abs_on, 0.01)};
}

// The true plane most of the fitted plane's inliers lie on, or when none
// does, the closest one; -1 if there is no true plane. Counts the inliers.
int BestTruePlane(const TexturedPlane& fitted, const FittedPlane& plane,
                  const Map& map, const Map& truth,
                  const std::vector<Assignment>& assignment,
                  const StructureAccuracyOptions& options, int* inliers) {
  std::vector<int> votes(truth.planes.size(), 0);
  for (size_t i = 0; i < map.landmarks.size(); ++i) {
    if (map.landmarks[i].plane_id != fitted.id) continue;
    ++*inliers;
    if (assignment[i].true_index >= 0) ++votes[assignment[i].true_index];
  }
  int best = -1;
  for (size_t j = 0; j < votes.size(); ++j) {
    if (votes[j] > 0 && (best < 0 || votes[j] > votes[best])) {
      best = static_cast<int>(j);
    }
  }
  if (best >= 0) return best;
  // No inlier on the structure: take the closest plane.
  double best_cost = std::numeric_limits<double>::infinity();
  for (size_t j = 0; j < truth.planes.size(); ++j) {
    double a, o;
    ComparePlanes(plane, truth.planes[j].plane, &a, &o);
    const double cost =
        a / options.max_match_angle_deg + o / options.max_match_offset_m;
    if (cost < best_cost) best_cost = cost, best = static_cast<int>(j);
  }
  return best;
}

// Keeps on the true plane the best of the fitted planes matched to it.
void RecordMatch(const PlaneMatch& m, TruePlaneResult* t) {
  const bool better =
      t->best_fitted_id < 0 || (m.matched && !t->matched) ||
      (m.matched == t->matched && m.normal_error_deg < t->normal_error_deg);
  t->matched = t->matched || m.matched;
  if (better) {
    t->best_fitted_id = m.fitted_id;
    t->normal_error_deg = m.normal_error_deg;
    t->offset_error_m = m.offset_error_m;
  }
}

// Each fitted plane is compared with the true plane most of its inliers lie
// on; returns the number of fitted planes that match theirs.
int MatchPlanes(const Map& map, const Map& truth, const Rigid3d& truth_from_map,
                const StructureAccuracyOptions& options,
                const std::vector<Assignment>& assignment,
                StructureAccuracy* result) {
  std::vector<double> normal_errors, offset_errors;
  int matched_fitted = 0;
  for (const TexturedPlane& fitted : map.planes) {
    PlaneMatch m;
    m.fitted_id = fitted.id;
    const FittedPlane plane = FittedInTruth(fitted, truth_from_map);
    const int best = BestTruePlane(fitted, plane, map, truth, assignment,
                                   options, &m.inliers);
    if (best >= 0) {
      m.true_id = truth.planes[best].id;
      ComparePlanes(plane, truth.planes[best].plane, &m.normal_error_deg,
                    &m.offset_error_m);
      m.matched = m.normal_error_deg <= options.max_match_angle_deg &&
                  m.offset_error_m <= options.max_match_offset_m;
      normal_errors.push_back(m.normal_error_deg);
      offset_errors.push_back(m.offset_error_m);
      if (m.matched) ++matched_fitted;
      RecordMatch(m, &result->true_plane_results[best]);
    }
    result->matches.push_back(m);
  }
  result->normal_error_deg = ComputeErrorStats(normal_errors);
  result->offset_error_m = ComputeErrorStats(offset_errors);
  return matched_fitted;
}

}  // namespace

StructureAccuracy EvaluateStructure(const Map& map, const Map& truth,
                                    const Rigid3d& truth_from_map,
                                    const StructureAccuracyOptions& options) {
  options.Check();
  StructureAccuracy result;
  result.true_planes = static_cast<int>(truth.planes.size());
  result.fitted_planes = static_cast<int>(map.planes.size());
  result.landmarks = static_cast<int>(map.landmarks.size());
  std::vector<Assignment> assignment;
  std::vector<int> near_count;
  ScorePoints(map, truth, truth_from_map, options, &assignment, &near_count,
              &result);

  result.true_plane_results.resize(truth.planes.size());
  for (size_t j = 0; j < truth.planes.size(); ++j) {
    TruePlaneResult& t = result.true_plane_results[j];
    t.true_id = truth.planes[j].id;
    t.near_landmarks = near_count[j];
    t.observed = near_count[j] >= options.min_observed_landmarks;
  }
  const int matched_fitted =
      MatchPlanes(map, truth, truth_from_map, options, assignment, &result);
  int observed_matched = 0;
  for (const TruePlaneResult& t : result.true_plane_results) {
    if (!t.observed) continue;
    ++result.observed_true_planes;
    if (t.matched) ++observed_matched;
  }
  result.precision = map.planes.empty()
                         ? 0.0
                         : static_cast<double>(matched_fitted) /
                               static_cast<double>(map.planes.size());
  result.coverage =
      MeasureAreaCoverage(map, truth, truth_from_map, options.coverage);
  result.recall =
      result.observed_true_planes == 0
          ? 0.0
          : static_cast<double>(observed_matched) / result.observed_true_planes;
  return result;
}

int SetLandmarkDepths(const std::vector<Track>& tracks, Map* map) {
  std::unordered_map<FeatureId, const Track*> track_by_id;
  for (const Track& t : tracks) track_by_id[t.id] = &t;
  const std::vector<TimedPose>& poses = map->trajectory;
  int from_tracks = 0;
  for (Landmark& l : map->landmarks) {
    const auto it = track_by_id.find(l.id);
    bool ok = it != track_by_id.end() && !it->second->observations.empty();
    double sum = 0.0;
    if (ok) {
      for (const Observation& o : it->second->observations) {
        if (o.frame < 0 || o.frame >= static_cast<int>(poses.size())) {
          ok = false;
          break;
        }
        sum +=
            (l.x_in_world - poses[o.frame].world_from_cam.translation).norm();
      }
    }
    if (ok) {
      l.mean_depth_m = sum / it->second->observations.size();
      ++from_tracks;
      continue;
    }
    double nearest =
        poses.empty() ? 0.0 : std::numeric_limits<double>::infinity();
    for (const TimedPose& p : poses) {
      nearest = std::min(nearest,
                         (l.x_in_world - p.world_from_cam.translation).norm());
    }
    l.mean_depth_m = nearest;
  }
  return from_tracks;
}

}  // namespace monomap
