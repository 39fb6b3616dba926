// Accuracy of reconstructed 3D points against ground truth: a plane (the
// desk) or a dense reference cloud (a surface scan).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <vector>

#include "monomap/geometry/plane.h"
#include "monomap/map/map.h"

namespace monomap {

// Summary of a set of non-negative error values.
struct ErrorStats {
  size_t count = 0;
  double mean = 0.0;
  // Middle value; the mean of the two middle values for an even count.
  double median = 0.0;
  // 90th percentile by the nearest-rank definition: the value at rank
  // ceil(0.9 * count) (1-based) of the sorted values.
  double p90 = 0.0;
  double max = 0.0;
  double rms = 0.0;  // sqrt(mean of squares)
};

// Statistics of `values` (all zero for an empty vector). Throws StageError
// if a value is not finite.
ErrorStats ComputeErrorStats(std::vector<double> values);

// Point errors in metres and relative to the distance to the camera.
struct PointAccuracy {
  ErrorStats absolute_m;
  // error / distance to camera * 100: scale-free, since depth error grows
  // with distance for a monocular reconstruction.
  ErrorStats relative_percent;
  // Fraction of the points whose absolute error exceeds 1 cm: the points a
  // user would call wrong, which a median hides.
  double share_above_1cm = 0.0;
};

// Fraction of `values` above `threshold` (0 for no values).
double ShareAbove(const std::vector<double>& values, double threshold);

// Absolute point-to-plane distances. `distance_to_camera_m` (same size as
// `points`, each > 0) gives the denominator of the relative error. Throws
// StageError on a size mismatch or a non-positive distance.
PointAccuracy EvaluatePointsAgainstPlane(
    const std::vector<Eigen::Vector3d>& points,
    const std::vector<double>& distance_to_camera_m, const Plane& plane);

// Exact nearest-neighbour search over a fixed reference cloud (a surface
// scan of hundreds of thousands of points). A KD-tree (median splits on the
// widest axis, small leaves, box pruning) rather than a uniform grid: a grid
// slows down badly for queries far from the cloud (outlier landmarks). Distances are exact and
// bit-identical to a brute-force scan (same arithmetic, exact pruning).
// Queries are thread-safe.
class NearestNeighborIndex {
 public:
  // Throws StageError if `cloud` is empty or holds a non-finite point.
  explicit NearestNeighborIndex(std::vector<Eigen::Vector3d> cloud);

  // Euclidean distance from `query` to the closest cloud point; its index
  // in the cloud goes to `index` if not null. Throws StageError for a
  // non-finite query.
  double NearestDistance(const Eigen::Vector3d& query,
                         size_t* index = nullptr) const;
  // NearestDistance for many queries, in parallel.
  std::vector<double> NearestDistances(
      const std::vector<Eigen::Vector3d>& queries) const;

  size_t size() const { return points_.size(); }

 private:
  struct Node {
    // Inner node: children `left`/`right`; points with coordinate `axis`
    // <= split are on the left, >= split on the right. Leaf: left == -1
    // and points_[begin, end).
    int axis = 0;
    double split = 0.0;
    int32_t left = -1, right = -1;
    uint32_t begin = 0, end = 0;
    // Bounding box of the node's points: far queries are pruned by the
    // distance to it (a split plane alone prunes little for them).
    Eigen::Vector3d lo, hi;
  };
  int32_t Build(uint32_t begin, uint32_t end);
  void Search(int32_t node, const Eigen::Vector3d& q, double* best_sq,
              uint32_t* best) const;
  double BoxSquaredDistance(int32_t node, const Eigen::Vector3d& q) const;

  std::vector<Eigen::Vector3d> points_;  // reordered into leaves
  std::vector<size_t> original_index_;   // points_[i] was cloud[...]
  std::vector<Node> nodes_;              // nodes_[0] is the root
};

// Distance of each point to its nearest reference cloud point. Same
// contract on `distance_to_camera_m` as EvaluatePointsAgainstPlane.
PointAccuracy EvaluatePointsAgainstCloud(
    const std::vector<Eigen::Vector3d>& points,
    const std::vector<double>& distance_to_camera_m,
    const NearestNeighborIndex& cloud);

// Distance from each point to the nearest camera centre of `trajectory`
// (the "distance to the camera" that relative errors divide by); infinity
// for an empty trajectory.
std::vector<double> DistanceToTrajectory(
    const std::vector<Eigen::Vector3d>& points,
    const std::vector<TimedPose>& trajectory);

// Plane label with the most landmarks (the lowest such label on a tie);
// nullopt if no landmark lies on a plane.
std::optional<int> LargestPlaneLabel(const Map& map);

// Selects all landmarks in LandmarkPositions.
inline constexpr int kAllLandmarks = -2;

// Positions of the landmarks with plane_id == `plane_label` (-1: on no
// plane; kAllLandmarks: every landmark), in map order.
std::vector<Eigen::Vector3d> LandmarkPositions(const Map& map, int plane_label);

// Reads the `plane: {normal: [nx, ny, nz], offset: d}` entry of a
// ground-truth structure YAML (n . X + d = 0; a non-unit normal is
// normalised together with d). Throws InputError naming file and field.
Plane ReadGroundTruthPlaneYaml(const std::filesystem::path& path);

}  // namespace monomap
