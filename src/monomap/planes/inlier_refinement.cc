#include "monomap/planes/inlier_refinement.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>
#include <utility>

#include "monomap/util/error.h"
#include "monomap/util/stats.h"

namespace monomap {

void InlierRefinementOptions::Check() const {
  CheckOption(neighbours >= 1, "inlier_refinement.neighbours", "must be >= 1");
}

namespace {

// The k nearest of a set of in-plane points, from a uniform grid sized so
// that a cell holds about k of them.
class NearestInPlane {
 public:
  NearestInPlane(const std::vector<Eigen::Vector2d>& st, int k)
      : st_(st), k_(k) {
    Eigen::Vector2d lo = st[0], hi = st[0];
    for (const auto& p : st) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    const Eigen::Vector2d size = hi - lo;
    const double n = static_cast<double>(st.size());
    // ~k points a cell over the box; a line of points (no area) gets
    // cells along its length.
    cell_ = std::max({std::sqrt(size.x() * size.y() * k / n),
                      size.maxCoeff() * k / n, 1e-9});
    lo_ = lo;
    nx_ = static_cast<int>(size.x() / cell_) + 1;
    ny_ = static_cast<int>(size.y() / cell_) + 1;
    start_.assign(static_cast<size_t>(nx_) * ny_ + 1, 0);
    for (const auto& p : st) ++start_[CellOf(p) + 1];
    for (size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
    members_.resize(st.size());
    std::vector<int> fill(start_.begin(), start_.end() - 1);
    for (int i = 0; i < static_cast<int>(st.size()); ++i) {
      members_[fill[CellOf(st[i])]++] = i;
    }
  }

  // Indices of the k points nearest to point i (itself included; all of
  // them if there are fewer). Rings of cells around i's cell are visited
  // until the k-th distance is below the ring's: no farther cell can hold
  // a nearer point.
  std::vector<int> Nearest(int i) const {
    const Eigen::Vector2d& q = st_[i];
    const int cx = CellX(q), cy = CellY(q);
    std::vector<std::pair<double, int>> found;
    const size_t k = std::min<size_t>(k_, st_.size());
    for (int r = 0; r <= std::max(nx_, ny_); ++r) {
      for (int y = cy - r; y <= cy + r; ++y) {
        for (int x = cx - r; x <= cx + r; ++x) {
          if (std::max(std::abs(x - cx), std::abs(y - cy)) != r) continue;
          if (x < 0 || y < 0 || x >= nx_ || y >= ny_) continue;
          const size_t c = static_cast<size_t>(y) * nx_ + x;
          for (size_t m = start_[c]; m < start_[c + 1]; ++m) {
            const int j = members_[m];
            found.emplace_back((st_[j] - q).squaredNorm(), j);
          }
        }
      }
      if (found.size() < k) continue;
      std::nth_element(found.begin(), found.begin() + (k - 1), found.end());
      const double reach = r * cell_;
      if (found[k - 1].first <= reach * reach) break;
    }
    found.resize(k);
    std::vector<int> idx;
    for (const auto& f : found) idx.push_back(f.second);
    return idx;
  }

 private:
  int CellX(const Eigen::Vector2d& p) const {
    return std::clamp(static_cast<int>((p.x() - lo_.x()) / cell_), 0, nx_ - 1);
  }
  int CellY(const Eigen::Vector2d& p) const {
    return std::clamp(static_cast<int>((p.y() - lo_.y()) / cell_), 0, ny_ - 1);
  }
  size_t CellOf(const Eigen::Vector2d& p) const {
    return static_cast<size_t>(CellY(p)) * nx_ + CellX(p);
  }

  const std::vector<Eigen::Vector2d>& st_;
  int k_;
  double cell_ = 1.0;
  Eigen::Vector2d lo_;
  int nx_ = 1, ny_ = 1;
  std::vector<size_t> start_;  // cell c's members: [start_[c], start_[c+1])
  std::vector<int> members_;
};

// The step that changes a point's signed distance by one unit at the least
// cost in its own uncertainty: conditioning a Gaussian of covariance `cov`
// on n . x moves it along cov n. Without a usable covariance: the normal.
Eigen::Vector3d MoveDirection(const Eigen::Matrix3d& cov,
                              const Eigen::Vector3d& normal) {
  const Eigen::Vector3d cn = cov * normal;
  const double ncn = normal.dot(cn);
  if (!(ncn > 0.0) || !cn.allFinite()) return normal;
  return cn / ncn;  // normal . step == 1
}

// Moves the landmarks `members` of one plane to their local offsets;
// appends each move's length and relative offset.
void RefineOnePlane(const PlaneSegment& segment, int neighbours,
                    const std::vector<int>& members,
                    std::vector<Landmark>* landmarks,
                    std::vector<double>* moves,
                    std::vector<double>* relative_offsets) {
  std::vector<Eigen::Vector2d> st;
  std::vector<double> offset;
  for (int m : members) {
    const Eigen::Vector3d& x = (*landmarks)[m].x_in_world;
    st.push_back(segment.frame.ToPlane(x));
    offset.push_back(segment.plane.SignedDistance(x));
  }
  const NearestInPlane index(st, neighbours);
  std::vector<double> excess(members.size());
  for (size_t i = 0; i < members.size(); ++i) {
    std::vector<double> near;
    for (int j : index.Nearest(static_cast<int>(i))) near.push_back(offset[j]);
    excess[i] = offset[i] - Median(std::move(near));
  }
  for (size_t i = 0; i < members.size(); ++i) {
    Landmark& l = (*landmarks)[members[i]];
    const Eigen::Vector3d step =
        excess[i] *
        MoveDirection(l.covariance_m2_per_px2, segment.plane.normal);
    l.x_in_world -= step;
    moves->push_back(step.norm());
    if (l.mean_depth_m > 0) {
      relative_offsets->push_back(std::abs(excess[i]) / l.mean_depth_m);
    }
  }
}

}  // namespace

InlierRefinementReport RefineInliersOnPlanes(
    const InlierRefinementOptions& options,
    const std::vector<PlaneSegment>& segments,
    std::vector<Landmark>* landmarks) {
  options.Check();
  InlierRefinementReport report;
  report.enabled = options.enabled;
  if (!options.enabled) return report;
  std::unordered_map<int, size_t> segment_of_id;
  for (size_t s = 0; s < segments.size(); ++s) {
    segment_of_id[segments[s].id] = s;
  }
  std::vector<std::vector<int>> members(segments.size());
  for (int i = 0; i < static_cast<int>(landmarks->size()); ++i) {
    const Landmark& l = (*landmarks)[i];
    const auto it = segment_of_id.find(l.plane_id);
    // A point that is not finite has no place on a plane; it stays.
    if (it != segment_of_id.end() && l.x_in_world.allFinite()) {
      members[it->second].push_back(i);
    }
  }
  std::vector<double> moves, relative_offsets;
  for (size_t s = 0; s < segments.size(); ++s) {
    if (members[s].empty()) continue;
    RefineOnePlane(segments[s], options.neighbours, members[s], landmarks,
                   &moves, &relative_offsets);
  }
  report.num_moved = static_cast<int>(moves.size());
  report.median_move_m = Median(moves);
  report.max_move_m =
      moves.empty() ? 0.0 : *std::max_element(moves.begin(), moves.end());
  report.median_relative_offset = Median(relative_offsets);
  return report;
}

}  // namespace monomap
