#include "monomap/planes/plane_hypotheses.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "monomap/geometry/polygon.h"
#include "monomap/planes/plane_directions.h"
#include "monomap/util/angles.h"
#include "monomap/util/error.h"

namespace monomap {

void PlaneHypothesisOptions::Check() const {
  CheckOption(min_points >= 3, "hypotheses.min_points", "must be >= 3");
  CheckOption(same_direction_deg >= 0 && same_direction_deg < 45,
              "hypotheses.same_direction_deg", "must be in [0, 45)");
  CheckOption(min_cross_angle_deg > 0 && min_cross_angle_deg <= 90,
              "hypotheses.min_cross_angle_deg", "must be in (0, 90]");
  CheckOption(neighbour_depth_fraction > 0, "hypotheses.neighbour_depth_fraction",
              "must be positive");
  CheckOption(near_segment_depth_fraction >= 0,
              "hypotheses.near_segment_depth_fraction", "must be >= 0");
  CheckOption(coplanar_max_angle_deg >= 0 && coplanar_max_angle_deg < 90,
              "hypotheses.coplanar_max_angle_deg", "must be in [0, 90)");
  CheckOption(normal_error_sigmas >= 0, "hypotheses.normal_error_sigmas",
              "must be >= 0");
  CheckOption(max_hypotheses >= 0, "hypotheses.max_hypotheses", "must be >= 0");
}

namespace {

// Whether unit direction d is one of `dirs` (up to sign) within cos_tol.
bool Known(const std::vector<Eigen::Vector3d>& dirs, const Eigen::Vector3d& d,
           double cos_tol) {
  for (const Eigen::Vector3d& e : dirs) {
    if (std::abs(e.dot(d)) >= cos_tol) return true;
  }
  return false;
}

// A landmark free for hypotheses: where it is and how loose.
struct FreePoint {
  int landmark = 0;
  Eigen::Vector3d x;
  double depth = 0.0;      // mean depth (m); > 0
  double threshold = 0.0;  // LandmarkInlierThreshold
};

// Band of a free point along unit normal n: its threshold, or its
// covariance band when wider (FitPlanes' absorb_consistent_points).
double Band(const PlaneFittingOptions& f, const std::vector<Landmark>& lms,
            const FreePoint& p, const Eigen::Vector3d& n) {
  return std::max(
      p.threshold,
      CovarianceBand(lms[p.landmark], n, f.covariance_sigmas * f.tracking_noise_px));
}

// Whether landmark l is explained by a segment already: within its band of
// the segment's plane, and on or near its polygon.
bool OnSegment(const PlaneHypothesisOptions& o, const PlaneFittingOptions& f,
               const std::vector<Landmark>& lms, const FreePoint& p,
               const std::vector<PlaneSegment>& segments) {
  for (const PlaneSegment& seg : segments) {
    if (std::abs(seg.plane.SignedDistance(p.x)) >
        Band(f, lms, p, seg.plane.normal)) {
      continue;
    }
    if (seg.polygon.size() < 3 ||
        DistanceToPolygon(seg.polygon, seg.frame.ToPlane(p.x)) <=
            o.near_segment_depth_fraction * p.depth) {
      return true;
    }
  }
  return false;
}

std::vector<FreePoint> FreePoints(const PlaneHypothesisOptions& o,
                                  const PlaneFittingOptions& f,
                                  const std::vector<Landmark>& lms,
                                  const std::vector<PlaneSegment>& segments) {
  std::vector<FreePoint> out;
  for (int i = 0; i < static_cast<int>(lms.size()); ++i) {
    const Landmark& l = lms[i];
    if (l.plane_id >= 0 || !l.x_in_world.allFinite() ||
        !(l.mean_depth_m > 0) || !std::isfinite(l.mean_depth_m)) {
      continue;
    }
    FreePoint p{i, l.x_in_world, l.mean_depth_m, LandmarkInlierThreshold(f, l)};
    if (!OnSegment(o, f, lms, p, segments)) out.push_back(p);
  }
  return out;
}

// The largest connected group (in-plane distance below the neighbour
// radius) among points `idx` of a plane with normal n.
std::vector<int> LargestGroup(const PlaneHypothesisOptions& o,
                              const std::vector<FreePoint>& pts,
                              const std::vector<int>& idx,
                              const Eigen::Vector3d& n) {
  std::vector<int> label(idx.size(), -1), best;
  for (size_t seed = 0; seed < idx.size(); ++seed) {
    if (label[seed] >= 0) continue;
    std::vector<int> group = {static_cast<int>(seed)};
    label[seed] = static_cast<int>(seed);
    for (size_t k = 0; k < group.size(); ++k) {
      const FreePoint& a = pts[idx[group[k]]];
      for (size_t j = 0; j < idx.size(); ++j) {
        if (label[j] >= 0) continue;
        const FreePoint& b = pts[idx[j]];
        const Eigen::Vector3d d = b.x - a.x;
        const double in_plane = (d - d.dot(n) * n).norm();
        if (in_plane < o.neighbour_depth_fraction * 0.5 * (a.depth + b.depth)) {
          label[j] = static_cast<int>(seed);
          group.push_back(static_cast<int>(j));
        }
      }
    }
    if (group.size() > best.size()) best = group;
  }
  for (int& k : best) k = idx[k];
  return best;
}

// The best supported offset along n among the points still free: for each
// point's offset, the points within their band of it; then its largest
// connected group.
std::vector<int> BestGroupAlong(const PlaneHypothesisOptions& o,
                                const PlaneFittingOptions& f,
                                const std::vector<Landmark>& lms,
                                const std::vector<FreePoint>& pts,
                                const std::vector<char>& used,
                                const Eigen::Vector3d& n) {
  const int m = static_cast<int>(pts.size());
  std::vector<double> s(m), band(m);
  for (int i = 0; i < m; ++i) {
    s[i] = n.dot(pts[i].x);
    band[i] = Band(f, lms, pts[i], n);
  }
  std::vector<int> best;
  for (int i = 0; i < m; ++i) {
    if (used[i]) continue;
    std::vector<int> idx;
    for (int j = 0; j < m; ++j) {
      if (!used[j] && std::abs(s[j] - s[i]) <= band[j]) idx.push_back(j);
    }
    if (idx.size() < static_cast<size_t>(o.min_points) || idx.size() <= best.size()) {
      continue;
    }
    std::vector<int> group = LargestGroup(o, pts, idx, n);
    if (group.size() > best.size()) best = std::move(group);
  }
  return best;
}

// Standard error (rad) of each segment's normal from its inliers
// (NormalStandardErrorRad; 0 when they are not among the landmarks).
std::vector<double> NormalErrors(const std::vector<Landmark>& lms,
                                 const std::vector<PlaneSegment>& segments) {
  std::unordered_map<FeatureId, int> index;
  for (int i = 0; i < static_cast<int>(lms.size()); ++i) index[lms[i].id] = i;
  std::vector<double> out;
  for (const PlaneSegment& seg : segments) {
    std::vector<Eigen::Vector3d> x;
    for (FeatureId id : seg.inlier_ids) {
      const auto it = index.find(id);
      if (it != index.end()) x.push_back(lms[it->second].x_in_world);
    }
    const double e = NormalStandardErrorRad(x);
    out.push_back(std::isfinite(e) ? e : 0.0);
  }
  return out;
}

// Whether the hypothesis is a segment's plane again: parallel, and at its
// centroid within its points' band of the segment's plane, widened by how
// far the segment's normal may tilt (normal_error_sigmas standard errors)
// over the distance from its polygon: a wall fitted over a few metres and
// seen again further along is the same wall, even where its fitted plane
// has drifted by centimetres.
bool CoplanarWithSegment(const PlaneHypothesisOptions& o,
                         const PlaneSegment& hyp, double band,
                         const std::vector<PlaneSegment>& segments,
                         const std::vector<double>& normal_errors) {
  const double cos_max = std::cos(DegToRad(o.coplanar_max_angle_deg));
  const Eigen::Vector3d c = hyp.frame.origin;
  for (size_t k = 0; k < segments.size(); ++k) {
    const PlaneSegment& seg = segments[k];
    if (std::abs(seg.plane.normal.dot(hyp.plane.normal)) < cos_max) continue;
    const double reach =
        seg.polygon.size() >= 3
            ? DistanceToPolygon(seg.polygon, seg.frame.ToPlane(c))
            : (c - seg.frame.origin).norm();
    const double tilt =
        std::tan(std::min(o.normal_error_sigmas * normal_errors[k], 0.5));
    if (std::abs(seg.plane.SignedDistance(c)) <= band + reach * tilt) {
      return true;
    }
  }
  return false;
}

// The hypothesis of a group along n: the median offset, facing the cameras.
PlaneSegment MakeHypothesis(const std::vector<Landmark>& lms,
                            const std::vector<FreePoint>& pts,
                            const std::vector<int>& group,
                            const Eigen::Vector3d& n,
                            const std::vector<Eigen::Vector3d>& centers) {
  PlaneSegment seg;
  std::vector<double> s;
  std::vector<Eigen::Vector3d> x;
  for (int k : group) {
    s.push_back(n.dot(pts[k].x));
    x.push_back(pts[k].x);
  }
  std::nth_element(s.begin(), s.begin() + s.size() / 2, s.end());
  seg.plane.normal = n;
  seg.plane.offset = -s[s.size() / 2];
  OrientPlane(&centers, &seg.plane);
  SetSegmentFrame(x, &seg);
  for (int k : group) {
    seg.inlier_ids.push_back(lms[pts[k].landmark].id);
    seg.inlier_st.push_back(seg.frame.ToPlane(pts[k].x));
  }
  seg.polygon = ConvexHull(seg.inlier_st);
  return seg;
}

}  // namespace

std::vector<Eigen::Vector3d> SceneDirections(
    const PlaneHypothesisOptions& options,
    const std::vector<PlaneSegment>& segments) {
  const double cos_same = std::cos(DegToRad(options.same_direction_deg));
  std::vector<Eigen::Vector3d> dirs;
  for (const PlaneSegment& seg : segments) {
    const Eigen::Vector3d n = seg.plane.normal.normalized();
    if (n.allFinite() && !Known(dirs, n, cos_same)) dirs.push_back(n);
  }
  const double sin_min = std::sin(DegToRad(options.min_cross_angle_deg));
  const size_t base = dirs.size();
  for (size_t i = 0; i < base; ++i) {
    for (size_t j = i + 1; j < base; ++j) {
      const Eigen::Vector3d c = dirs[i].cross(dirs[j]);
      if (c.norm() < sin_min) continue;
      if (!Known(dirs, c.normalized(), cos_same)) dirs.push_back(c.normalized());
    }
  }
  return dirs;
}

std::vector<PlaneSegment> ProposePlaneHypotheses(
    const PlaneHypothesisOptions& options, const PlaneFittingOptions& fitting,
    const std::vector<Landmark>& landmarks,
    const std::vector<PlaneSegment>& segments,
    const std::vector<Eigen::Vector3d>& camera_centers) {
  options.Check();
  fitting.Check();
  const std::vector<Eigen::Vector3d> dirs = SceneDirections(options, segments);
  const std::vector<FreePoint> pts =
      FreePoints(options, fitting, landmarks, segments);
  const std::vector<double> normal_errors = NormalErrors(landmarks, segments);
  std::vector<char> used(pts.size(), 0);
  std::vector<PlaneSegment> out;
  while (static_cast<int>(out.size()) < options.max_hypotheses) {
    std::vector<int> best;
    Eigen::Vector3d best_dir = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& n : dirs) {
      std::vector<int> g = BestGroupAlong(options, fitting, landmarks, pts, used, n);
      if (g.size() > best.size()) {
        best = std::move(g);
        best_dir = n;
      }
    }
    if (best.size() < static_cast<size_t>(options.min_points)) break;
    for (int k : best) used[k] = 1;
    PlaneSegment seg =
        MakeHypothesis(landmarks, pts, best, best_dir, camera_centers);
    std::vector<double> bands;
    for (int k : best) bands.push_back(Band(fitting, landmarks, pts[k], best_dir));
    std::nth_element(bands.begin(), bands.begin() + bands.size() / 2, bands.end());
    if (CoplanarWithSegment(options, seg, bands[bands.size() / 2], segments,
                            normal_errors)) {
      continue;
    }
    seg.id = static_cast<int>(segments.size() + out.size());
    out.push_back(std::move(seg));
  }
  return out;
}

}  // namespace monomap
