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

// Grid cell of an in-plane position, packed into one key.
uint64_t CellKey(double a, double b, double cell) {
  const auto i = static_cast<uint64_t>(static_cast<int64_t>(std::floor(a / cell)));
  const auto j = static_cast<uint64_t>(static_cast<int64_t>(std::floor(b / cell)));
  return (i << 32) ^ (j & 0xffffffffu);
}

// The largest connected group (in-plane distance below the neighbour
// radius) among points `idx` (ascending) of the scan's plane; ties go to
// the group of the first point. A grid of cells as wide as the largest
// radius finds the neighbours, visited in index order.
std::vector<int> LargestGroup(const PlaneHypothesisOptions& o,
                              const std::vector<FreePoint>& pts,
                              const std::vector<int>& idx,
                              const DirectionScan& scan) {
  double max_depth = 0.0;
  for (int k : idx) max_depth = std::max(max_depth, pts[k].depth);
  // A hair wider than the largest radius, so rounding never hides one.
  const double cell =
      std::max(o.neighbour_depth_fraction * max_depth * (1.0 + 1e-9), 1e-9);
  std::unordered_map<uint64_t, std::vector<int>> grid;
  std::vector<Eigen::Vector2d> uv;
  for (size_t j = 0; j < idx.size(); ++j) {
    const Eigen::Vector3d& x = pts[idx[j]].x;
    uv.emplace_back(scan.u.dot(x), scan.v.dot(x));
    grid[CellKey(uv[j].x(), uv[j].y(), cell)].push_back(static_cast<int>(j));
  }
  std::vector<int> label(idx.size(), -1), best;
  for (size_t seed = 0; seed < idx.size(); ++seed) {
    if (label[seed] >= 0) continue;
    std::vector<int> group = {static_cast<int>(seed)};
    label[seed] = static_cast<int>(seed);
    for (size_t k = 0; k < group.size(); ++k) {
      const FreePoint& a = pts[idx[group[k]]];
      const Eigen::Vector2d& c = uv[group[k]];
      std::vector<int> found;
      for (int di = -1; di <= 1; ++di) {
        for (int dj = -1; dj <= 1; ++dj) {
          const auto it = grid.find(
              CellKey(c.x() + di * cell, c.y() + dj * cell, cell));
          if (it == grid.end()) continue;
          for (int j : it->second) {
            if (label[j] >= 0) continue;
            const FreePoint& b = pts[idx[j]];
            const Eigen::Vector3d d = b.x - a.x;
            const double in_plane = (d - d.dot(scan.n) * scan.n).norm();
            if (in_plane <
                o.neighbour_depth_fraction * 0.5 * (a.depth + b.depth)) {
              found.push_back(j);
            }
          }
        }
      }
      std::sort(found.begin(), found.end());
      for (int j : found) label[j] = static_cast<int>(seed);
      group.insert(group.end(), found.begin(), found.end());
    }
    if (group.size() > best.size()) best = group;
  }
  for (int& k : best) k = idx[k];
  return best;
}

// The unused points within their band of point i's offset, ascending.
// `by_s` orders the points by offset; `max_band` bounds every band.
std::vector<int> PointsAtOffset(const DirectionScan& scan,
                                const std::vector<char>& used,
                                const std::vector<int>& by_s, double max_band,
                                int i) {
  const double si = scan.s[i];
  const double reach = max_band * (1.0 + 1e-9) + 1e-12;  // never too short
  auto it = std::lower_bound(
      by_s.begin(), by_s.end(), si - reach,
      [&](int j, double value) { return scan.s[j] < value; });
  std::vector<int> idx;
  for (; it != by_s.end() && scan.s[*it] <= si + reach; ++it) {
    const int j = *it;
    if (!used[j] && std::abs(scan.s[j] - si) <= scan.band[j]) idx.push_back(j);
  }
  std::sort(idx.begin(), idx.end());
  return idx;
}

// Along one direction, each free point's offset proposes the largest
// connected group among the points within their band of it. A round takes
// a few points, which changes the groups of the offsets near theirs only,
// so the group sizes are kept and recomputed where they may have changed:
// the proposal costs about one pass over the points, not one per round.
class OffsetGroups {
 public:
  OffsetGroups(const PlaneHypothesisOptions& o,
               const std::vector<FreePoint>& pts, DirectionScan scan)
      : o_(o), pts_(pts), scan_(std::move(scan)),
        size_(pts.size(), 0), stale_(pts.size(), 1) {
    for (int i = 0; i < static_cast<int>(pts.size()); ++i) by_s_.push_back(i);
    std::sort(by_s_.begin(), by_s_.end(),
              [&](int a, int b) { return scan_.s[a] < scan_.s[b]; });
    for (double b : scan_.band) max_band_ = std::max(max_band_, b);
  }

  const Eigen::Vector3d& direction() const { return scan_.n; }

  // The best group among the points not `used`: the largest, ties to the
  // first point's offset (points fewer than min_points at an offset
  // propose none). Empty if no offset proposes one.
  std::vector<int> Best(const std::vector<char>& used) {
    int best_i = -1;
    for (int i = 0; i < static_cast<int>(pts_.size()); ++i) {
      if (used[i]) continue;
      if (stale_[i]) Refresh(used, i);
      if (size_[i] > (best_i < 0 ? 0 : size_[best_i])) best_i = i;
    }
    if (best_i < 0) return {};
    return LargestGroup(o_, pts_, At(used, best_i), scan_);
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
  std::vector<int> At(const std::vector<char>& used, int i) const {
    return PointsAtOffset(scan_, used, by_s_, max_band_, i);
  }
  void Refresh(const std::vector<char>& used, int i) {
    const std::vector<int> idx = At(used, i);
    size_[i] = idx.size() < static_cast<size_t>(o_.min_points)
                   ? 0
                   : static_cast<int>(LargestGroup(o_, pts_, idx, scan_).size());
    stale_[i] = 0;
  }

  const PlaneHypothesisOptions& o_;
  const std::vector<FreePoint>& pts_;
  DirectionScan scan_;
  std::vector<int> by_s_;
  double max_band_ = 0.0;
  std::vector<int> size_;   // group size of each point's offset
  std::vector<char> stale_;  // size_ to recompute
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
