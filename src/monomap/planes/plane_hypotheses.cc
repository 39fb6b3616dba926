#include "monomap/planes/plane_hypotheses.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
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

// The free points seen along one scene direction: each one's offset along
// it and its band, computed once for every round of the proposal.
struct DirectionScan {
  Eigen::Vector3d n, u, v;  // the direction and an in-plane basis
  std::vector<double> s, band;
};

DirectionScan ScanAlong(const PlaneFittingOptions& f,
                        const std::vector<Landmark>& lms,
                        const std::vector<FreePoint>& pts,
                        const Eigen::Vector3d& n) {
  DirectionScan scan;
  scan.n = n;
  scan.u = n.unitOrthogonal();
  scan.v = n.cross(scan.u);
  for (const FreePoint& p : pts) {
    scan.s.push_back(n.dot(p.x));
    scan.band.push_back(Band(f, lms, p, n));
  }
  return scan;
}

// Along one direction, each free point's offset proposes the connected
// group through that point (neighbours closer in the plane than a quarter
// of their depth) of the points within their band of the offset. A round
// takes a few points, which changes the groups of the offsets near theirs
// only, so the group sizes are kept and recomputed where they may have
// changed; a grid over the plane and the offset finds the neighbours. The
// proposal so costs about one pass over the points, not one per round,
// and each group what its neighbourhood holds.
class OffsetGroups {
 public:
  OffsetGroups(const PlaneHypothesisOptions& o,
               const std::vector<FreePoint>& pts, DirectionScan scan)
      : o_(o), pts_(pts), scan_(std::move(scan)), size_(pts.size(), 0),
        stale_(pts.size(), 1), visited_(pts.size(), -1) {
    double max_depth = 0.0, max_band = 0.0;
    for (const FreePoint& p : pts) max_depth = std::max(max_depth, p.depth);
    for (double b : scan_.band) max_band = std::max(max_band, b);
    // A hair wider than the largest radius and band, so that rounding
    // never hides a neighbour.
    cell_ = std::max(o.neighbour_depth_fraction * max_depth * (1 + 1e-9), 1e-9);
    cell_s_ = std::max(max_band * (1 + 1e-9), 1e-9);
    for (int i = 0; i < static_cast<int>(pts.size()); ++i) {
      grid_[Key(Cell(i))].push_back(i);
      by_s_.push_back(i);
    }
    std::sort(by_s_.begin(), by_s_.end(),
              [&](int a, int b) { return scan_.s[a] < scan_.s[b]; });
  }

  const Eigen::Vector3d& direction() const { return scan_.n; }

  // The best group among the points not `used`: the largest, ties to the
  // first point's. Empty when every point is used.
  std::vector<int> Best(const std::vector<char>& used) {
    int best_i = -1;
    for (int i = 0; i < static_cast<int>(pts_.size()); ++i) {
      if (used[i]) continue;
      if (stale_[i]) {
        size_[i] = static_cast<int>(GroupAt(used, i).size());
        stale_[i] = 0;
      }
      if (best_i < 0 || size_[i] > size_[best_i]) best_i = i;
    }
    if (best_i < 0) return {};
    return GroupAt(used, best_i);
  }

  // Marks stale the offsets whose points included newly used point j.
  void Take(int j) {
    const double reach = scan_.band[j] * (1.0 + 1e-9) + 1e-12;
    auto it = std::lower_bound(
        by_s_.begin(), by_s_.end(), scan_.s[j] - reach,
        [&](int k, double value) { return scan_.s[k] < value; });
    for (; it != by_s_.end() && scan_.s[*it] <= scan_.s[j] + reach; ++it) {
      stale_[*it] = 1;
    }
  }

 private:
  Eigen::Vector3i Cell(int i) const {
    const Eigen::Vector3d& x = pts_[i].x;
    return {static_cast<int>(std::floor(scan_.u.dot(x) / cell_)),
            static_cast<int>(std::floor(scan_.v.dot(x) / cell_)),
            static_cast<int>(std::floor(scan_.s[i] / cell_s_))};
  }
  static uint64_t Key(const Eigen::Vector3i& c) {
    const auto bits = [](int v) { return static_cast<uint64_t>(v) & 0x1fffff; };
    return (bits(c.x()) << 42) | (bits(c.y()) << 21) | bits(c.z());
  }

  // The points connected to point i among the unused ones within their
  // band of its offset, ascending.
  std::vector<int> GroupAt(const std::vector<char>& used, int i) {
    ++stamp_;
    std::vector<int> group = {i};
    visited_[i] = stamp_;
    for (size_t k = 0; k < group.size(); ++k) {
      const FreePoint& a = pts_[group[k]];
      const Eigen::Vector3i c = Cell(group[k]);
      for (int d = 0; d < 27; ++d) {
        const auto it = grid_.find(
            Key(c + Eigen::Vector3i(d % 3 - 1, d / 3 % 3 - 1, d / 9 - 1)));
        if (it == grid_.end()) continue;
        for (int j : it->second) {
          if (used[j] || visited_[j] == stamp_ ||
              !(std::abs(scan_.s[j] - scan_.s[i]) <= scan_.band[j])) {
            continue;
          }
          const FreePoint& b = pts_[j];
          const Eigen::Vector3d x = b.x - a.x;
          const double in_plane = (x - x.dot(scan_.n) * scan_.n).norm();
          if (in_plane < o_.neighbour_depth_fraction * 0.5 * (a.depth + b.depth)) {
            visited_[j] = stamp_;
            group.push_back(j);
          }
        }
      }
    }
    std::sort(group.begin(), group.end());
    return group;
  }

  const PlaneHypothesisOptions& o_;
  const std::vector<FreePoint>& pts_;
  DirectionScan scan_;
  double cell_ = 1.0;    // grid cell side in the plane (m)
  double cell_s_ = 1.0;  // ... and along the direction (m)
  std::unordered_map<uint64_t, std::vector<int>> grid_;
  std::vector<int> by_s_;    // points by offset
  std::vector<int> size_;    // group size of each point's offset
  std::vector<char> stale_;  // size_ to recompute
  std::vector<int> visited_;  // stamp of the last search that reached it
  int stamp_ = 0;
};

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
  std::vector<OffsetGroups> along;
  for (const Eigen::Vector3d& n : dirs) {
    along.emplace_back(options, pts, ScanAlong(fitting, landmarks, pts, n));
  }
  std::vector<char> used(pts.size(), 0);
  std::vector<PlaneSegment> out;
  while (static_cast<int>(out.size()) < options.max_hypotheses) {
    std::vector<int> best;
    Eigen::Vector3d best_dir = Eigen::Vector3d::Zero();
    for (OffsetGroups& groups : along) {
      std::vector<int> g = groups.Best(used);
      if (g.size() > best.size()) {
        best = std::move(g);
        best_dir = groups.direction();
      }
    }
    if (best.size() < static_cast<size_t>(options.min_points)) break;
    for (int k : best) {
      used[k] = 1;
      for (OffsetGroups& groups : along) groups.Take(k);
    }
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
