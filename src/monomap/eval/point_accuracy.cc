#include "monomap/eval/point_accuracy.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <string>

#include "monomap/util/error.h"
#include "monomap/util/file.h"
#include "monomap/util/stats.h"

namespace monomap {
namespace fs = std::filesystem;

ErrorStats ComputeErrorStats(std::vector<double> values) {
  ErrorStats s;
  s.count = values.size();
  if (values.empty()) return s;
  for (const double v : values) {
    if (!std::isfinite(v)) {
      throw StageError("ComputeErrorStats: non-finite error value");
    }
  }
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  double sum = 0.0, sum_sq = 0.0;
  for (const double v : values) {
    sum += v;
    sum_sq += v * v;
  }
  s.mean = sum / n;
  s.rms = std::sqrt(sum_sq / n);
  s.median = Median(values);
  // Nearest rank ceil(0.9 n), computed in integers to avoid 0.9 * 10 =
  // 9.000...01 rounding up to rank 10.
  const size_t rank = (9 * n + 9) / 10;
  s.p90 = values[std::max<size_t>(rank, 1) - 1];
  s.max = values.back();
  return s;
}

double ShareAbove(const std::vector<double>& values, double threshold) {
  if (values.empty()) return 0.0;
  const auto above = std::count_if(values.begin(), values.end(),
                                   [&](double v) { return v > threshold; });
  return static_cast<double>(above) / static_cast<double>(values.size());
}

namespace {

PointAccuracy AccuracyFromErrors(const std::vector<double>& errors,
                                 const std::vector<double>& distances) {
  std::vector<double> relative(errors.size());
  for (size_t i = 0; i < errors.size(); ++i) {
    relative[i] = errors[i] / distances[i] * 100.0;
  }
  PointAccuracy acc;
  acc.absolute_m = ComputeErrorStats(errors);
  acc.share_above_1cm = ShareAbove(errors, 0.01);
  acc.relative_percent = ComputeErrorStats(std::move(relative));
  return acc;
}

void CheckDistances(size_t num_points, const std::vector<double>& distances) {
  if (distances.size() != num_points) {
    throw StageError("point accuracy: " + std::to_string(num_points) +
                     " points but " + std::to_string(distances.size()) +
                     " camera distances");
  }
  for (const double d : distances) {
    if (!(d > 0.0) || !std::isfinite(d)) {
      throw StageError(
          "point accuracy: distance to camera must be finite and > 0");
    }
  }
}

// Explicit sum so that every caller computes bit-identical distances.
inline double SquaredDistance(const Eigen::Vector3d& a,
                              const Eigen::Vector3d& b) {
  const double dx = a.x() - b.x(), dy = a.y() - b.y(), dz = a.z() - b.z();
  return dx * dx + dy * dy + dz * dz;
}

}  // namespace

PointAccuracy EvaluatePointsAgainstPlane(
    const std::vector<Eigen::Vector3d>& points,
    const std::vector<double>& distance_to_camera_m, const Plane& plane) {
  CheckDistances(points.size(), distance_to_camera_m);
  const double norm = plane.normal.norm();
  if (!(norm > 0.0)) throw StageError("point accuracy: zero plane normal");
  std::vector<double> errors(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    errors[i] = std::abs(plane.SignedDistance(points[i])) / norm;
  }
  return AccuracyFromErrors(errors, distance_to_camera_m);
}

PointAccuracy EvaluatePointsAgainstCloud(
    const std::vector<Eigen::Vector3d>& points,
    const std::vector<double>& distance_to_camera_m,
    const NearestNeighborIndex& cloud) {
  CheckDistances(points.size(), distance_to_camera_m);
  return AccuracyFromErrors(cloud.NearestDistances(points),
                            distance_to_camera_m);
}

// ---------------------------------------------------------------------------
// NearestNeighborIndex

namespace {
constexpr uint32_t kLeafSize = 12;
}  // namespace

NearestNeighborIndex::NearestNeighborIndex(std::vector<Eigen::Vector3d> cloud)
    : points_(std::move(cloud)) {
  if (points_.empty()) throw StageError("NearestNeighborIndex: empty cloud");
  if (points_.size() >= std::numeric_limits<uint32_t>::max()) {
    throw StageError("NearestNeighborIndex: cloud too large");
  }
  for (const auto& p : points_) {
    if (!p.allFinite()) {
      throw StageError("NearestNeighborIndex: non-finite cloud point");
    }
  }
  original_index_.resize(points_.size());
  std::iota(original_index_.begin(), original_index_.end(), size_t{0});
  nodes_.reserve(2 * (points_.size() / kLeafSize + 1));
  Build(0, static_cast<uint32_t>(points_.size()));
}

int32_t NearestNeighborIndex::Build(uint32_t begin, uint32_t end) {
  const int32_t id = static_cast<int32_t>(nodes_.size());
  nodes_.emplace_back();
  nodes_[id].begin = begin;
  nodes_[id].end = end;
  Eigen::Vector3d lo = points_[begin], hi = points_[begin];
  for (uint32_t i = begin; i < end; ++i) {
    lo = lo.cwiseMin(points_[i]);
    hi = hi.cwiseMax(points_[i]);
  }
  nodes_[id].lo = lo;
  nodes_[id].hi = hi;
  if (end - begin <= kLeafSize) return id;
  int axis = 0;
  (hi - lo).maxCoeff(&axis);
  if (hi[axis] == lo[axis]) return id;  // all points equal: one leaf
  // Median split; points_ and original_index_ are permuted together.
  const uint32_t mid = begin + (end - begin) / 2;
  std::vector<uint32_t> order(end - begin);
  std::iota(order.begin(), order.end(), begin);
  std::nth_element(order.begin(), order.begin() + (mid - begin), order.end(),
                   [&](uint32_t a, uint32_t b) {
                     const double pa = points_[a][axis], pb = points_[b][axis];
                     return pa != pb ? pa < pb : a < b;
                   });
  std::vector<Eigen::Vector3d> pts(order.size());
  std::vector<size_t> idx(order.size());
  for (size_t k = 0; k < order.size(); ++k) {
    pts[k] = points_[order[k]];
    idx[k] = original_index_[order[k]];
  }
  std::copy(pts.begin(), pts.end(), points_.begin() + begin);
  std::copy(idx.begin(), idx.end(), original_index_.begin() + begin);
  const double split = points_[mid][axis];
  const int32_t left = Build(begin, mid);
  const int32_t right = Build(mid, end);
  Node& node = nodes_[id];  // Build() may have reallocated nodes_
  node.axis = axis;
  node.split = split;
  node.left = left;
  node.right = right;
  return id;
}

double NearestNeighborIndex::BoxSquaredDistance(
    int32_t id, const Eigen::Vector3d& q) const {
  // Same operations and summation order as SquaredDistance, and rounding
  // is monotone, so this never exceeds the computed distance of a point in
  // the box: pruning on it is exact.
  const Node& n = nodes_[id];
  double d[3];
  for (int a = 0; a < 3; ++a) {
    d[a] = q[a] < n.lo[a] ? n.lo[a] - q[a]
           : q[a] > n.hi[a] ? q[a] - n.hi[a]
                            : 0.0;
  }
  return d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
}

void NearestNeighborIndex::Search(int32_t id, const Eigen::Vector3d& q,
                                  double* best_sq, uint32_t* best) const {
  const Node& node = nodes_[id];
  if (node.left < 0) {
    for (uint32_t i = node.begin; i < node.end; ++i) {
      const double d = SquaredDistance(points_[i], q);
      if (d < *best_sq) {
        *best_sq = d;
        *best = i;
      }
    }
    return;
  }
  // Nearer child first; a child whose box is no closer than the best
  // point cannot hold a strictly closer one.
  const double dl = BoxSquaredDistance(node.left, q);
  const double dr = BoxSquaredDistance(node.right, q);
  const bool left_first = dl <= dr;
  const int32_t first = left_first ? node.left : node.right;
  const int32_t second = left_first ? node.right : node.left;
  if ((left_first ? dl : dr) < *best_sq) Search(first, q, best_sq, best);
  if ((left_first ? dr : dl) < *best_sq) Search(second, q, best_sq, best);
}

double NearestNeighborIndex::NearestDistance(const Eigen::Vector3d& q,
                                             size_t* index) const {
  if (!q.allFinite()) {
    throw StageError("NearestNeighborIndex: non-finite query point");
  }
  double best_sq = std::numeric_limits<double>::infinity();
  uint32_t best = 0;
  Search(0, q, &best_sq, &best);
  if (index) *index = original_index_[best];
  return std::sqrt(best_sq);
}

std::vector<double> NearestNeighborIndex::NearestDistances(
    const std::vector<Eigen::Vector3d>& queries) const {
  std::vector<double> out(queries.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, queries.size(), 256),
                    [&](const tbb::blocked_range<size_t>& range) {
                      for (size_t i = range.begin(); i != range.end(); ++i) {
                        out[i] = NearestDistance(queries[i]);
                      }
                    });
  return out;
}

// ---------------------------------------------------------------------------
// Ground-truth YAML

std::vector<double> DistanceToTrajectory(
    const std::vector<Eigen::Vector3d>& points,
    const std::vector<TimedPose>& trajectory) {
  std::vector<double> d(points.size(), std::numeric_limits<double>::infinity());
  for (size_t i = 0; i < points.size(); ++i) {
    for (const auto& p : trajectory) {
      d[i] = std::min(d[i], (points[i] - p.world_from_cam.translation).norm());
    }
  }
  return d;
}

std::optional<int> LargestPlaneLabel(const Map& map) {
  std::map<int, int> counts;
  for (const auto& l : map.landmarks) {
    if (l.plane_id >= 0) ++counts[l.plane_id];
  }
  if (counts.empty()) return std::nullopt;
  return std::max_element(counts.begin(), counts.end(),
                          [](auto& a, auto& b) { return a.second < b.second; })
      ->first;
}

std::vector<Eigen::Vector3d> LandmarkPositions(const Map& map,
                                               int plane_label) {
  std::vector<Eigen::Vector3d> xs;
  for (const auto& l : map.landmarks) {
    if (plane_label == kAllLandmarks || l.plane_id == plane_label) {
      xs.push_back(l.x_in_world);
    }
  }
  return xs;
}

Plane ReadGroundTruthPlaneYaml(const fs::path& path) {
  const std::string file = path.string();
  const std::string text = ReadFileToString(path);
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError(file, e.mark.line + 1, "malformed YAML: " + e.msg);
  }
  const YAML::Node plane = root.IsMap() ? root["plane"] : YAML::Node();
  if (!plane || !plane.IsMap()) {
    throw InputError(file, "plane", "missing or not a map");
  }
  const YAML::Node normal = plane["normal"];
  if (!normal || !normal.IsSequence() || normal.size() != 3) {
    throw InputError(file, "plane.normal", "expected a list of 3 numbers");
  }
  Eigen::Vector3d n;
  double offset = 0.0;
  try {
    for (int i = 0; i < 3; ++i) n[i] = normal[i].as<double>();
  } catch (const YAML::Exception&) {
    throw InputError(file, "plane.normal", "value is not a number");
  }
  const YAML::Node off = plane["offset"];
  if (!off) throw InputError(file, "plane.offset", "missing");
  try {
    offset = off.as<double>();
  } catch (const YAML::Exception&) {
    throw InputError(file, "plane.offset", "not a number");
  }
  if (!n.allFinite() || !std::isfinite(offset)) {
    throw InputError(file, "plane", "value is not finite");
  }
  const double norm = n.norm();
  if (norm < 1e-12) throw InputError(file, "plane.normal", "zero vector");
  Plane p;
  p.normal = n / norm;
  p.offset = offset / norm;
  return p;
}

}  // namespace monomap
