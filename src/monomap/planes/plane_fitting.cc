#include "monomap/planes/plane_fitting.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <unordered_map>

#include "monomap/geometry/polygon.h"
#include "monomap/planes/cell_outline.h"
#include "monomap/planes/plane_directions.h"
#include "monomap/util/angles.h"
#include "monomap/util/error.h"
#include "monomap/util/progress.h"
#include "monomap/util/stats.h"

namespace monomap {

void PlaneFittingOptions::Check() const {
  CheckOption(ransac_iterations > 0, "planes.ransac_iterations", "must be > 0");
  CheckOption(min_threshold_m > 0, "planes.min_threshold_m", "must be > 0");
  CheckOption(relative_threshold >= 0, "planes.relative_threshold",
              "must be >= 0");
  CheckOption(max_threshold_m >= min_threshold_m, "planes.max_threshold_m",
              "must be >= min_threshold_m");
  CheckOption(refine_iterations >= 0, "planes.refine_iterations",
              "must be >= 0");
  CheckOption(min_inliers >= 3, "planes.min_inliers", "must be >= 3");
  CheckOption(min_inlier_fraction >= 0 && min_inlier_fraction < 1,
              "planes.min_inlier_fraction", "must be in [0, 1)");
  CheckOption(std::isfinite(connectivity_radius_m),
              "planes.connectivity_radius_m", "must be finite");
  CheckOption(connectivity_factor > 0, "planes.connectivity_factor",
              "must be > 0");
  CheckOption(min_connectivity_radius_m > 0, "planes.min_connectivity_radius_m",
              "must be > 0");
  CheckOption(max_connectivity_radius_m >= min_connectivity_radius_m,
              "planes.max_connectivity_radius_m",
              "must be >= min_connectivity_radius_m");
  CheckOption(max_planes > 0, "planes.max_planes", "must be > 0");
  CheckOption(ghost_max_angle_deg >= 0, "planes.ghost_max_angle_deg",
              "must be >= 0");
  CheckOption(ghost_distance_factor >= 0, "planes.ghost_distance_factor",
              "must be >= 0");
  CheckOption(max_consecutive_failures >= 1, "planes.max_consecutive_failures",
              "must be >= 1");
  CheckOption(tracking_noise_px >= 0 && std::isfinite(tracking_noise_px),
              "planes.tracking_noise_px", "must be finite and >= 0");
  CheckOption(covariance_sigmas >= 0 && std::isfinite(covariance_sigmas),
              "planes.covariance_sigmas", "must be finite and >= 0");
  CheckOption(max_extension_rounds >= 1, "planes.max_extension_rounds",
              "must be >= 1");
  CheckOption(polygon_cell_factor > 0, "planes.polygon_cell_factor",
              "must be > 0");
  CheckOption(snap_max_angle_deg >= 0 && snap_max_angle_deg < 90,
              "planes.snap_max_angle_deg", "must be in [0, 90)");
  CheckOption(snap_min_kept_fraction >= 0 && snap_min_kept_fraction <= 1,
              "planes.snap_min_kept_fraction", "must be in [0, 1]");
  CheckOption(direction_max_error_deg >= 0 &&
                  std::isfinite(direction_max_error_deg),
              "planes.direction_max_error_deg", "must be finite and >= 0");
  CheckOption(merge_max_angle_deg >= 0 && merge_max_angle_deg < 90,
              "planes.merge_max_angle_deg", "must be in [0, 90)");
  CheckOption(merge_max_offset_m >= 0 && std::isfinite(merge_max_offset_m),
              "planes.merge_max_offset_m", "must be finite and >= 0");
  CheckOption(merge_max_gap_m >= 0 && std::isfinite(merge_max_gap_m),
              "planes.merge_max_gap_m", "must be finite and >= 0");
  CheckOption(merge_max_offset_thresholds >= 0 &&
                  std::isfinite(merge_max_offset_thresholds),
              "planes.merge_max_offset_thresholds", "must be finite and >= 0");
}

double CovarianceBand(const Landmark& l, const Eigen::Vector3d& n, double k) {
  const double var = n.dot(l.covariance_m2_per_px2 * n);
  return std::isfinite(var) && var > 0 ? k * std::sqrt(var) : 0.0;
}

double LandmarkInlierThreshold(const PlaneFittingOptions& o,
                               const Landmark& l) {
  const double depth = l.mean_depth_m;
  if (!std::isfinite(depth) || depth <= 0) return o.min_threshold_m;
  return std::clamp(o.relative_threshold * depth, o.min_threshold_m,
                    o.max_threshold_m);
}

void OrientPlane(const std::vector<Eigen::Vector3d>* camera_centers,
                 Plane* plane) {
  bool flip = plane->offset < 0;
  if (camera_centers != nullptr && !camera_centers->empty()) {
    int votes = 0;
    double sum = 0.0;
    for (const auto& c : *camera_centers) {
      const double d = plane->SignedDistance(c);
      votes += d > 0 ? 1 : (d < 0 ? -1 : 0);
      sum += d;
    }
    flip = votes < 0 || (votes == 0 && sum < 0);
  }
  if (flip) {
    plane->normal = -plane->normal;
    plane->offset = -plane->offset;
  }
}

void SetSegmentFrame(const std::vector<Eigen::Vector3d>& cpts,
                     PlaneSegment* seg) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const auto& p : cpts) c += p;
  c /= static_cast<double>(cpts.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  double sq = 0.0;
  for (const auto& p : cpts) {
    const double dist = seg->plane.SignedDistance(p);
    sq += dist * dist;
    const Eigen::Vector3d d = (p - c) - dist * seg->plane.normal;
    scatter += d * d.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(scatter);
  Eigen::Vector3d u = eig.eigenvectors().col(2);
  Eigen::Index big;
  u.cwiseAbs().maxCoeff(&big);
  if (u(big) < 0) u = -u;  // canonical sign: deterministic frames
  seg->frame = MakePlaneFrame(seg->plane, c, u);
  seg->rms_distance_m = std::sqrt(sq / cpts.size());
}

namespace {

// Uniform hash grid over 2D points for fixed-radius neighbour queries.
class Grid2d {
 public:
  Grid2d(const std::vector<Eigen::Vector2d>& points, double cell)
      : inv_cell_(1.0 / cell) {
    for (size_t i = 0; i < points.size(); ++i) {
      const auto [cx, cy] = CellOf(points[i]);
      cells_[Key(cx, cy)].push_back(static_cast<int>(i));
    }
  }
  // Calls fn(j) for every point j in the 3x3 cells around p.
  template <typename Fn>
  void ForNearby(const Eigen::Vector2d& p, Fn&& fn) const {
    const auto [cx, cy] = CellOf(p);
    for (int64_t dx = -1; dx <= 1; ++dx) {
      for (int64_t dy = -1; dy <= 1; ++dy) {
        const auto it = cells_.find(Key(cx + dx, cy + dy));
        if (it == cells_.end()) continue;
        for (int j : it->second) fn(j);
      }
    }
  }

 private:
  std::pair<int64_t, int64_t> CellOf(const Eigen::Vector2d& p) const {
    return {static_cast<int64_t>(std::floor(p.x() * inv_cell_)),
            static_cast<int64_t>(std::floor(p.y() * inv_cell_))};
  }
  static int64_t Key(int64_t x, int64_t y) {
    return (x << 32) ^ (y & 0xffffffffLL);
  }
  double inv_cell_;
  std::unordered_map<int64_t, std::vector<int>> cells_;
};

// Median distance of each point to its nearest neighbour. A grid whose cell
// is twice the mean spacing finds the neighbour of all but isolated points,
// which the median ignores anyway.
double MedianNearestNeighbourSpacing(const std::vector<Eigen::Vector2d>& st) {
  Eigen::Vector2d lo = st[0], hi = st[0];
  for (const auto& p : st) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const Eigen::Vector2d ext = (hi - lo).cwiseMax(1e-9);
  const double mean_spacing = std::sqrt(ext.x() * ext.y() / st.size());
  const double cell = std::max(2.0 * mean_spacing, 1e-9);
  Grid2d grid(st, cell);
  std::vector<double> nn;
  nn.reserve(st.size());
  for (size_t i = 0; i < st.size(); ++i) {
    double best = std::numeric_limits<double>::infinity();
    grid.ForNearby(st[i], [&](int j) {
      if (static_cast<size_t>(j) == i) return;
      best = std::min(best, (st[j] - st[i]).squaredNorm());
    });
    if (std::isfinite(best)) nn.push_back(std::sqrt(best));
  }
  if (nn.empty()) return cell;
  return UpperMedian(std::move(nn));
}

int FindRoot(std::vector<int>& parent, int i) {
  while (parent[i] != i) {
    parent[i] = parent[parent[i]];
    i = parent[i];
  }
  return i;
}

// Connected components of the points under "distance < radius". Returns the
// components as index lists, largest first (ties: smallest first index).
std::vector<std::vector<int>> ConnectedComponents(
    const std::vector<Eigen::Vector2d>& st, double radius) {
  const int n = static_cast<int>(st.size());
  std::vector<int> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  Grid2d grid(st, radius);
  const double r2 = radius * radius;
  for (int i = 0; i < n; ++i) {
    grid.ForNearby(st[i], [&](int j) {
      if (j <= i || (st[j] - st[i]).squaredNorm() >= r2) return;
      const int a = FindRoot(parent, i), b = FindRoot(parent, j);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    });
  }
  std::unordered_map<int, int> slot;
  std::vector<std::vector<int>> comps;
  for (int i = 0; i < n; ++i) {
    const int root = FindRoot(parent, i);
    auto [it, fresh] = slot.emplace(root, static_cast<int>(comps.size()));
    if (fresh) comps.emplace_back();
    comps[it->second].push_back(i);
  }
  std::stable_sort(
      comps.begin(), comps.end(),
      [](const auto& a, const auto& b) { return a.size() > b.size(); });
  return comps;
}

// Outline of the occupancy grid of the points (cell size `cell`), closed
// morphologically so sampling gaps do not punch holes; falls back to the
// convex hull when the grid is degenerate.
Polygon2d OccupancyOutline(const std::vector<Eigen::Vector2d>& st,
                           double cell) {
  Eigen::Vector2d lo = st[0], hi = st[0];
  for (const auto& p : st) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  // Centre the grid on the points so the cells overhang equally on both
  // sides.
  for (int a = 0; a < 2; ++a) {
    const double extent = hi(a) - lo(a);
    lo(a) -= 0.5 * ((std::floor(extent / cell) + 1) * cell - extent);
  }
  const int margin = 2;
  const double cols_d = (hi.x() - lo.x()) / cell + 2 * margin + 1;
  const double rows_d = (hi.y() - lo.y()) / cell + 2 * margin + 1;
  if (cols_d * rows_d > 2.5e5) return ConvexHull(st);  // too fine: stay cheap
  cv::Mat1b cells =
      cv::Mat1b::zeros(static_cast<int>(rows_d), static_cast<int>(cols_d));
  for (const auto& p : st) {
    const int c = static_cast<int>((p.x() - lo.x()) / cell) + margin;
    const int r = static_cast<int>((p.y() - lo.y()) / cell) + margin;
    cells(r, c) = 255;
  }
  cv::morphologyEx(cells, cells, cv::MORPH_CLOSE,
                   cv::getStructuringElement(cv::MORPH_RECT, {3, 3}));
  Polygon2d poly = OutlineOfCells(cells, lo, cell, margin);
  return poly.empty() ? ConvexHull(st) : poly;
}

// Outline of the union of polygons (one plane's coordinates), with gaps up
// to `bridge` between them filled: the untextured stretch between two
// pieces of one wall is wall too. Falls back to the convex hull of all
// vertices.
Polygon2d MergedOutline(const std::vector<Polygon2d>& polygons,
                        double bridge) {
  std::vector<Eigen::Vector2d> all;
  for (const Polygon2d& p : polygons) all.insert(all.end(), p.begin(), p.end());
  Eigen::Vector2d lo = all[0], hi = all[0];
  for (const auto& v : all) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  // About 400 cells along the longer side, never finer than 1 cm.
  const double cell = std::max(0.01, (hi - lo).maxCoeff() / 400.0);
  const int close_r = static_cast<int>(std::ceil(0.5 * bridge / cell)) + 1;
  const int margin = close_r + 1;
  const Eigen::Vector2d origin = lo - margin * cell * Eigen::Vector2d::Ones();
  cv::Mat1b cells = cv::Mat1b::zeros(
      static_cast<int>((hi.y() - lo.y()) / cell) + 2 * margin + 1,
      static_cast<int>((hi.x() - lo.x()) / cell) + 2 * margin + 1);
  constexpr int kShift = 4;  // sub-cell vertex precision for fillPoly
  for (const Polygon2d& p : polygons) {
    std::vector<cv::Point> pts;
    for (const auto& v : p) {
      // Pixel c covers [c - 0.5, c + 0.5) for fillPoly, [c, c + 1) here.
      const Eigen::Vector2d c =
          ((v - origin) / cell - Eigen::Vector2d(0.5, 0.5)) * (1 << kShift);
      pts.emplace_back(static_cast<int>(std::lround(c.x())),
                       static_cast<int>(std::lround(c.y())));
    }
    cv::fillPoly(cells, std::vector<std::vector<cv::Point>>{pts}, 255,
                 cv::LINE_8, kShift);
  }
  cv::morphologyEx(cells, cells, cv::MORPH_CLOSE,
                   cv::getStructuringElement(
                       cv::MORPH_RECT, {2 * close_r + 1, 2 * close_r + 1}));
  Polygon2d poly = OutlineOfCells(cells, lo, cell, margin);
  return poly.empty() ? ConvexHull(all) : poly;
}

uint64_t MixSeed(uint64_t seed, uint64_t k) {
  // splitmix64 step: decorrelates the seeds of successive RANSAC runs.
  uint64_t z = seed + 0x9e3779b97f4a7c15ULL * (k + 1);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// The state FitPlanes' stages share: the landmarks still in the search, their
// thresholds, and the segments found so far.
struct FitState {
  FitState(const PlaneFittingOptions& o, std::vector<Landmark>& l,
           std::vector<PlaneSegment>* segs,
           const std::vector<Eigen::Vector3d>* centers, PlaneFittingReport* r)
      : options(o),
        lms(l),
        segments(segs),
        camera_centers(centers),
        report(r) {}
  const PlaneFittingOptions& options;
  std::vector<Landmark>& lms;
  std::vector<PlaneSegment>* segments;
  const std::vector<Eigen::Vector3d>* camera_centers;
  PlaneFittingReport* report;
  std::vector<double> thresholds;      // per landmark
  std::vector<int> remaining;          // landmarks still searched
  std::vector<char> taken;             // on a segment or set aside
  std::vector<Eigen::Vector3d> pts{};  // x_in_world of `remaining`
  std::vector<double> inv_thr{};       // 1 / threshold of `remaining`
  std::vector<Eigen::Vector3d> directions{};  // well-determined normals
  size_t min_count = 0;
};

// Per-landmark threshold; invalid points never enter the search.
void InitSearch(FitState* s) {
  const PlaneFittingOptions& o = s->options;
  const int n = static_cast<int>(s->lms.size());
  s->thresholds.assign(n, o.min_threshold_m);
  s->taken.assign(n, 0);
  s->remaining.reserve(n);
  for (int i = 0; i < n; ++i) {
    s->lms[i].plane_id = -1;
    if (!s->lms[i].x_in_world.allFinite()) continue;
    s->thresholds[i] = LandmarkInlierThreshold(o, s->lms[i]);
    s->remaining.push_back(i);
  }
  s->min_count = static_cast<size_t>(
      std::max<double>(o.min_inliers, std::ceil(o.min_inlier_fraction * n)));
}

// Least squares on the inliers, re-selecting them each time.
void RefineHypothesis(const FitState& s, const PlaneEstimator& estimator,
                      Plane* plane, std::vector<size_t>* inliers) {
  std::vector<Eigen::Vector3d> inlier_pts;
  for (int it = 0; it < s.options.refine_iterations; ++it) {
    inlier_pts.clear();
    for (size_t k : *inliers) inlier_pts.push_back(s.pts[k]);
    const Plane refined = FitPlaneLeastSquares(inlier_pts);
    std::vector<size_t> reselected;
    for (size_t k = 0; k < s.pts.size(); ++k) {
      if (estimator.Residual(refined, k) <= 1.0) reselected.push_back(k);
    }
    if (reselected.size() < 3) break;
    *plane = refined;
    if (reselected == *inliers) break;
    *inliers = std::move(reselected);
  }
}

// A "ghost": nearly the same plane as an accepted segment, made of the
// points just outside that segment's threshold (its noisier points). They
// are outliers of the real plane, not a second surface. With
// local_ghost_test only the points over the segment's polygon count.
bool IsGhost(const FitState& s, const Plane& plane,
             const std::vector<size_t>& inliers) {
  for (const PlaneSegment& seg : *s.segments) {
    if (PlaneAngle(seg.plane, plane) > DegToRad(s.options.ghost_max_angle_deg)) {
      continue;
    }
    double dist = 0.0, thr = 0.0;
    size_t over = 0;
    for (size_t k : inliers) {
      if (s.options.local_ghost_test &&
          !PointInPolygon(seg.polygon, seg.frame.ToPlane(s.pts[k]))) {
        continue;
      }
      ++over;
      dist += std::abs(seg.plane.SignedDistance(s.pts[k]));
      thr += 1.0 / s.inv_thr[k];
    }
    if (2 * over >= inliers.size() &&
        dist < s.options.ghost_distance_factor * thr) {
      return true;
    }
  }
  return false;
}

// Splits the inliers into connected regions of the plane; *radius is the
// connectivity radius used.
std::vector<std::vector<int>> SplitRegions(const FitState& s,
                                           const Plane& plane,
                                           const std::vector<size_t>& inliers,
                                           double* radius) {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (size_t k : inliers) centroid += s.pts[k];
  centroid /= static_cast<double>(inliers.size());
  const PlaneFrame split_frame =
      MakePlaneFrame(plane, centroid, plane.normal.unitOrthogonal());
  std::vector<Eigen::Vector2d> st(inliers.size());
  for (size_t k = 0; k < inliers.size(); ++k) {
    st[k] = split_frame.ToPlane(s.pts[inliers[k]]);
  }
  *radius = s.options.connectivity_radius_m;
  if (*radius <= 0) {
    *radius = std::clamp(
        s.options.connectivity_factor * MedianNearestNeighbourSpacing(st),
        s.options.min_connectivity_radius_m,
        s.options.max_connectivity_radius_m);
  }
  return ConnectedComponents(st, *radius);
}

// Marks remaining outliers consistent with `seg` (within their uncertainty
// and near its polygon) as taken, so no later plane claims them. With
// extend_to_absorbed they also bound it: the polygon is redrawn over the
// inliers and the absorbed points, which brings the next ones within
// reach, for up to max_extension_rounds rounds; the inliers' own outline
// stays as landmark_polygon.
void AbsorbConsistent(double radius, FitState* s, PlaneSegment* seg) {
  const PlaneFittingOptions& o = s->options;
  const double k = o.covariance_sigmas * o.tracking_noise_px;
  const Polygon2d fitted = seg->polygon;
  std::vector<Eigen::Vector2d> support = seg->inlier_st;
  const int rounds = o.extend_to_absorbed ? o.max_extension_rounds : 1;
  for (int round = 0; round < rounds; ++round) {
    const size_t before = support.size();
    for (int lm : s->remaining) {
      if (s->taken[lm]) continue;
      const Eigen::Vector3d& x = s->lms[lm].x_in_world;
      const double band = std::max(
          s->thresholds[lm], CovarianceBand(s->lms[lm], seg->plane.normal, k));
      if (std::abs(seg->plane.SignedDistance(x)) > band) continue;
      const Eigen::Vector2d q = seg->frame.ToPlane(x);
      if (DistanceToPolygon(seg->polygon, q) <= radius) {
        s->taken[lm] = 1;
        ++s->report->absorbed;
        support.push_back(q);
      }
    }
    if (!o.extend_to_absorbed || support.size() == before) break;
    seg->polygon =
        o.concave_polygon
            ? OccupancyOutline(support, o.polygon_cell_factor * radius)
            : ConvexHull(support);
  }
  if (seg->polygon != fitted) seg->landmark_polygon = fitted;
}

// The plane of a segment's points: least squares, snapped to the scene's
// directions when enabled and the points allow it. With `learn`, a
// well-determined normal becomes a direction itself and the snap is
// reported.
Plane FitSegmentPlane(const std::vector<Eigen::Vector3d>& cpts,
                      const std::vector<int>& lms, int id, bool learn,
                      FitState* s) {
  const PlaneFittingOptions& o = s->options;
  if (!o.snap_to_directions) return FitPlaneLeastSquares(cpts);
  // Each point's sigma along the plane's normal: a third of its uncertainty
  // band (AbsorbConsistent).
  const Eigen::Vector3d n = FitPlaneLeastSquares(cpts).normal;
  const double k = o.covariance_sigmas * o.tracking_noise_px;
  std::vector<double> sigmas(lms.size());
  for (size_t i = 0; i < lms.size(); ++i) {
    sigmas[i] = std::max(s->thresholds[lms[i]],
                         CovarianceBand(s->lms[lms[i]], n, k)) /
                std::max(o.covariance_sigmas, 1.0);
  }
  DirectionSnapOptions snap_options;
  snap_options.max_angle_rad = DegToRad(o.snap_max_angle_deg);
  snap_options.band_sigmas = std::max(o.covariance_sigmas, 1.0);
  snap_options.min_kept_fraction = o.snap_min_kept_fraction;
  const DirectionSnap snap =
      SnapToDirections(cpts, sigmas, s->directions, snap_options);
  if (!learn) return snap.plane;
  if (snap.kind != DirectionSnap::Kind::kNone) {
    s->report->snaps.push_back({id, DirectionSnapKindName(snap.kind),
                                snap.angle_deg, snap.kept_fraction});
  }
  if (snap.kind != DirectionSnap::Kind::kParallel &&
      NormalStandardErrorRad(cpts) <= DegToRad(o.direction_max_error_deg)) {
    s->directions.push_back(snap.plane.normal);
  }
  return snap.plane;
}

// Turns one connected region of a hypothesis' inliers into a segment.
void AddSegment(const std::vector<size_t>& inliers,
                const std::vector<int>& comp, double radius, FitState* s) {
  PlaneSegment seg;
  seg.id = static_cast<int>(s->segments->size());
  std::vector<Eigen::Vector3d> cpts;
  cpts.reserve(comp.size());
  std::vector<int> lms;
  for (int c : comp) {
    cpts.push_back(s->pts[inliers[c]]);
    lms.push_back(s->remaining[inliers[c]]);
  }
  seg.plane = FitSegmentPlane(cpts, lms, seg.id, /*learn=*/true, s);
  OrientPlane(s->camera_centers, &seg.plane);
  SetSegmentFrame(cpts, &seg);
  seg.inlier_ids.reserve(comp.size());
  seg.inlier_st.reserve(comp.size());
  for (int k : comp) {
    const int lm = s->remaining[inliers[k]];
    s->lms[lm].plane_id = seg.id;
    s->taken[lm] = 1;
    seg.inlier_ids.push_back(s->lms[lm].id);
    seg.inlier_st.push_back(seg.frame.ToPlane(s->lms[lm].x_in_world));
  }
  seg.polygon = s->options.concave_polygon
                    ? OccupancyOutline(seg.inlier_st,
                                       s->options.polygon_cell_factor * radius)
                    : ConvexHull(seg.inlier_st);
  s->report->inliers_per_plane.push_back(static_cast<int>(comp.size()));
  if (s->options.absorb_consistent_points) AbsorbConsistent(radius, s, &seg);
  s->segments->push_back(std::move(seg));
}

// Sets the points of a rejected hypothesis aside so the next one differs.
void SetAside(const std::vector<size_t>& inliers, FitState* s) {
  ++s->report->rejected_hypotheses;
  for (size_t k : inliers) s->taken[s->remaining[k]] = 1;
}

enum class Attempt { kAccepted, kRejected, kExhausted };

// One RANSAC hypothesis over the remaining points: refined, checked for a
// ghost, split into regions, each big enough region kept as a segment.
Attempt TryHypothesis(int attempt, FitState* s) {
  const PlaneFittingOptions& o = s->options;
  s->pts.resize(s->remaining.size());
  s->inv_thr.resize(s->remaining.size());
  for (size_t k = 0; k < s->remaining.size(); ++k) {
    s->pts[k] = s->lms[s->remaining[k]].x_in_world;
    s->inv_thr[k] = 1.0 / s->thresholds[s->remaining[k]];
  }
  const PlaneEstimator estimator{&s->pts, &s->inv_thr};
  RansacOptions ransac;
  ransac.max_iterations = o.ransac_iterations;
  ransac.min_iterations = std::min(ransac.min_iterations, o.ransac_iterations);
  ransac.inlier_threshold = 1.0;
  ransac.confidence = 1.0;
  ransac.seed = MixSeed(o.seed, attempt);
  const auto best = Ransac(estimator, ransac);
  s->report->iterations += best.iterations;
  // The best plane is too small: the rest is noise.
  if (!best.success || best.inliers.size() < s->min_count) {
    return Attempt::kExhausted;
  }
  Plane plane = best.model;
  std::vector<size_t> inliers = best.inliers;
  RefineHypothesis(*s, estimator, &plane, &inliers);
  if (IsGhost(*s, plane, inliers)) {
    SetAside(inliers, s);
    return Attempt::kRejected;
  }
  double radius = 0.0;
  bool accepted = false;
  for (const auto& comp : SplitRegions(*s, plane, inliers, &radius)) {
    if (comp.size() < s->min_count ||
        static_cast<int>(s->segments->size()) >= o.max_planes) {
      ++s->report->discarded_regions;
      continue;
    }
    accepted = true;
    AddSegment(inliers, comp, radius, s);
  }
  // No coherent region: a plane through clutter.
  if (!accepted) SetAside(inliers, s);
  return accepted ? Attempt::kAccepted : Attempt::kRejected;
}

// Landmark indices of a segment's inliers (index by id).
std::vector<int> InlierLandmarks(
    const std::unordered_map<FeatureId, int>& index, const PlaneSegment& seg) {
  std::vector<int> out;
  out.reserve(seg.inlier_ids.size());
  for (FeatureId id : seg.inlier_ids) out.push_back(index.at(id));
  return out;
}

double Median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

double MedianDistance(const Plane& plane,
                      const std::vector<Eigen::Vector3d>& x) {
  std::vector<double> d(x.size());
  for (size_t i = 0; i < x.size(); ++i) {
    d[i] = std::abs(plane.SignedDistance(x[i]));
  }
  return Median(std::move(d));
}

// Smallest distance between the polygons of a and b, in a's plane.
// Smallest in-plane distance between polygon pa of segment a and pb of b.
double PolygonGap(const PlaneSegment& a, const Polygon2d& pa,
                  const PlaneSegment& b, const Polygon2d& pb) {
  double gap = std::numeric_limits<double>::infinity();
  for (const Eigen::Vector2d& v : pb) {
    gap = std::min(gap,
                   DistanceToPolygon(pa, a.frame.ToPlane(b.frame.ToWorld(v))));
  }
  for (const Eigen::Vector2d& v : pa) {
    gap = std::min(gap,
                   DistanceToPolygon(pb, b.frame.ToPlane(a.frame.ToWorld(v))));
  }
  return gap;
}

double PolygonGap(const PlaneSegment& a, const PlaneSegment& b) {
  return PolygonGap(a, a.polygon, b, b.polygon);
}

// What a segment's inliers support: its polygon unless that was extended.
const Polygon2d& SupportedPolygon(const PlaneSegment& seg) {
  return seg.landmark_polygon.empty() ? seg.polygon : seg.landmark_polygon;
}

// A segment while merging: its inlier positions and its id as fitted.
struct MergeItem {
  std::vector<Eigen::Vector3d> pts;
  std::vector<int> lms;  // landmark index of each of pts
  int fitted_id = 0;
};

// Median inlier threshold of a segment's points.
double MedianThreshold(const FitState& s, const MergeItem& item) {
  std::vector<double> t(item.lms.size());
  for (size_t k = 0; k < t.size(); ++k) t[k] = s.thresholds[item.lms[k]];
  return Median(std::move(t));
}

// Median over a segment's points of their distance to `plane` in units of
// their own inlier threshold.
double MedianRelativeDistance(const FitState& s, const Plane& plane,
                              const MergeItem& item) {
  std::vector<double> d(item.pts.size());
  for (size_t k = 0; k < d.size(); ++k) {
    d[k] =
        std::abs(plane.SignedDistance(item.pts[k])) / s.thresholds[item.lms[k]];
  }
  return Median(std::move(d));
}

// Whether a and b are one physical plane: normals and offsets agree within
// the noise (centroids and each one's inliers against the other's fit, in
// metres and in the points' own thresholds) and their supports touch.
// Fills the merge record's angle and offsets, and *gap.
bool SameSurface(const FitState& s, const PlaneSegment& a, const MergeItem& ia,
                 const PlaneSegment& b, const MergeItem& ib,
                 PlaneFittingReport::Merge* m, double* gap) {
  const PlaneFittingOptions& o = s.options;
  m->angle_deg = RadToDeg(PlaneAngle(a.plane, b.plane));
  if (m->angle_deg > o.merge_max_angle_deg) return false;
  const double a_off = std::abs(b.plane.SignedDistance(a.frame.origin));
  const double b_off = std::abs(a.plane.SignedDistance(b.frame.origin));
  m->offset_m = std::max({a_off, b_off, MedianDistance(b.plane, ia.pts),
                          MedianDistance(a.plane, ib.pts)});
  m->offset_thresholds =
      std::max({a_off / MedianThreshold(s, ia), b_off / MedianThreshold(s, ib),
                MedianRelativeDistance(s, b.plane, ia),
                MedianRelativeDistance(s, a.plane, ib)});
  if (m->offset_m > o.merge_max_offset_m ||
      m->offset_thresholds > o.merge_max_offset_thresholds) {
    return false;
  }
  *gap = PolygonGap(a, b);
  return *gap <= o.merge_max_gap_m;
}

// A polygon of `seg` in world coordinates.
std::vector<Eigen::Vector3d> InWorld(const PlaneSegment& seg,
                                     const Polygon2d& polygon) {
  std::vector<Eigen::Vector3d> out;
  for (const Eigen::Vector2d& v : polygon) out.push_back(seg.frame.ToWorld(v));
  return out;
}

// World polygons in `seg`'s plane coordinates.
std::vector<Polygon2d> InPlane(
    const PlaneSegment& seg,
    const std::vector<std::vector<Eigen::Vector3d>>& outlines) {
  std::vector<Polygon2d> polygons(outlines.size());
  for (size_t i = 0; i < outlines.size(); ++i) {
    for (const Eigen::Vector3d& x : outlines[i]) {
      polygons[i].push_back(seg.frame.ToPlane(x));
    }
  }
  return polygons;
}

// Refits a (plane, frame, in-plane coordinates) to the points of a and b
// and bounds it by the union of their polygons, bridging `gap`; the same
// for what their inliers support, if either was extended.
void MergeInto(const MergeItem& item, const PlaneSegment& b, double gap,
               FitState* s, PlaneSegment* a) {
  const std::vector<std::vector<Eigen::Vector3d>> outlines = {
      InWorld(*a, a->polygon), InWorld(b, b.polygon)};
  const bool extended =
      !a->landmark_polygon.empty() || !b.landmark_polygon.empty();
  const double supported_gap =
      PolygonGap(*a, SupportedPolygon(*a), b, SupportedPolygon(b));
  const std::vector<std::vector<Eigen::Vector3d>> supported = {
      InWorld(*a, SupportedPolygon(*a)), InWorld(b, SupportedPolygon(b))};
  a->inlier_ids.insert(a->inlier_ids.end(), b.inlier_ids.begin(),
                       b.inlier_ids.end());
  a->plane = FitSegmentPlane(item.pts, item.lms, a->id, /*learn=*/false, s);
  OrientPlane(s->camera_centers, &a->plane);
  SetSegmentFrame(item.pts, a);
  a->inlier_st.resize(item.pts.size());
  for (size_t k = 0; k < item.pts.size(); ++k) {
    a->inlier_st[k] = a->frame.ToPlane(item.pts[k]);
  }
  a->polygon = MergedOutline(InPlane(*a, outlines), gap);
  a->landmark_polygon.clear();
  if (extended) {
    a->landmark_polygon = MergedOutline(InPlane(*a, supported), supported_gap);
  }
}

// Merges the first pair of segments that are one surface; false if none.
bool MergeOnePair(FitState* s, std::vector<MergeItem>* items) {
  std::vector<PlaneSegment>& segs = *s->segments;
  for (size_t i = 0; i < segs.size(); ++i) {
    for (size_t j = i + 1; j < segs.size(); ++j) {
      PlaneFittingReport::Merge m;
      MergeItem& a = (*items)[i];
      const MergeItem& b = (*items)[j];
      double gap = 0.0;
      if (!SameSurface(*s, segs[i], a, segs[j], b, &m, &gap)) {
        continue;
      }
      m.kept_id = a.fitted_id;
      m.merged_id = b.fitted_id;
      s->report->merges.push_back(m);
      a.pts.insert(a.pts.end(), b.pts.begin(), b.pts.end());
      a.lms.insert(a.lms.end(), b.lms.begin(), b.lms.end());
      MergeInto(a, segs[j], gap, s, &segs[i]);
      segs.erase(segs.begin() + j);
      items->erase(items->begin() + j);
      return true;
    }
  }
  return false;
}

// One map plane per physical plane: RANSAC and the connectivity split can
// cut one wall into pieces; merge them and renumber the segments.
void MergeCoplanar(FitState* s) {
  std::vector<PlaneSegment>& segs = *s->segments;
  std::unordered_map<FeatureId, int> index;
  for (int i = 0; i < static_cast<int>(s->lms.size()); ++i) {
    index[s->lms[i].id] = i;
  }
  std::vector<MergeItem> items;
  for (const PlaneSegment& seg : segs) {
    MergeItem item{{}, InlierLandmarks(index, seg), seg.id};
    for (int lm : item.lms) item.pts.push_back(s->lms[lm].x_in_world);
    items.push_back(std::move(item));
  }
  while (MergeOnePair(s, &items)) {
  }
  s->report->inliers_per_plane.clear();
  for (size_t k = 0; k < segs.size(); ++k) {
    segs[k].id = static_cast<int>(k);
    for (FeatureId id : segs[k].inlier_ids)
      s->lms[index.at(id)].plane_id = segs[k].id;
    s->report->inliers_per_plane.push_back(
        static_cast<int>(segs[k].inlier_ids.size()));
  }
}

}  // namespace

PlaneFittingReport FitPlanes(
    const PlaneFittingOptions& options, std::vector<Landmark>* landmarks,
    std::vector<PlaneSegment>* segments,
    const std::vector<Eigen::Vector3d>* camera_centers) {
  options.Check();
  Timer timer;
  PlaneFittingReport report;
  segments->clear();
  FitState s(options, *landmarks, segments, camera_centers, &report);
  report.num_points = static_cast<int>(landmarks->size());
  InitSearch(&s);
  int failures = 0;
  for (int attempt = 0;
       static_cast<int>(segments->size()) < options.max_planes &&
       s.remaining.size() >= s.min_count &&
       failures < options.max_consecutive_failures;
       ++attempt) {
    const Attempt result = TryHypothesis(attempt, &s);
    if (result == Attempt::kExhausted) break;
    failures = result == Attempt::kAccepted ? 0 : failures + 1;
    std::erase_if(s.remaining, [&](int i) { return s.taken[i] != 0; });
  }
  if (options.merge_coplanar) MergeCoplanar(&s);
  report.num_directions = static_cast<int>(s.directions.size());
  report.num_planes = static_cast<int>(segments->size());
  report.num_outliers = 0;
  for (const auto& lm : *landmarks) {
    report.num_outliers += lm.plane_id < 0 ? 1 : 0;
  }
  report.seconds = timer.ElapsedSeconds();
  return report;
}

}  // namespace monomap
