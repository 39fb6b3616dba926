#include "monomap/eval/point_accuracy.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <random>

#include "monomap/util/error.h"
#include "monomap/util/random.h"

namespace monomap {
namespace {

TEST(ErrorStatsTest, OddCount) {
  const ErrorStats s = ComputeErrorStats({5.0, 1.0, 3.0});
  EXPECT_EQ(s.count, 3u);
  EXPECT_DOUBLE_EQ(s.mean, 3.0);
  EXPECT_DOUBLE_EQ(s.median, 3.0);
  EXPECT_DOUBLE_EQ(s.p90, 5.0);  // rank ceil(2.7) = 3
  EXPECT_DOUBLE_EQ(s.max, 5.0);
  EXPECT_DOUBLE_EQ(s.rms, std::sqrt(35.0 / 3.0));
}

TEST(ErrorStatsTest, EvenCountMedianIsMeanOfMiddleValues) {
  const ErrorStats s = ComputeErrorStats({4.0, 1.0, 3.0, 2.0});
  EXPECT_DOUBLE_EQ(s.median, 2.5);
  EXPECT_DOUBLE_EQ(s.p90, 4.0);  // rank ceil(3.6) = 4
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
}

TEST(ErrorStatsTest, P90IsNearestRank) {
  std::vector<double> v;
  for (int i = 10; i >= 1; --i) v.push_back(i);
  EXPECT_DOUBLE_EQ(ComputeErrorStats(v).p90, 9.0);  // rank 9 exactly
  for (int i = 11; i <= 20; ++i) v.push_back(i);
  EXPECT_DOUBLE_EQ(ComputeErrorStats(v).p90, 18.0);  // rank 18
  v.push_back(21);
  EXPECT_DOUBLE_EQ(ComputeErrorStats(v).p90, 19.0);  // rank ceil(18.9) = 19
  EXPECT_DOUBLE_EQ(ComputeErrorStats({7.0}).p90, 7.0);
}

TEST(ErrorStatsTest, EmptyAndNonFinite) {
  const ErrorStats s = ComputeErrorStats({});
  EXPECT_EQ(s.count, 0u);
  EXPECT_EQ(s.rms, 0.0);
  EXPECT_THROW(ComputeErrorStats({1.0, std::nan("")}), StageError);
  EXPECT_THROW(
      ComputeErrorStats({std::numeric_limits<double>::infinity()}),
      StageError);
}

TEST(PointAccuracyTest, PlaneWithKnownOffsets) {
  Plane plane;
  plane.normal = Eigen::Vector3d(1, 2, 2).normalized();
  plane.offset = -0.7;
  Eigen::Vector3d u = plane.normal.unitOrthogonal();
  Eigen::Vector3d v = plane.normal.cross(u);
  const Eigen::Vector3d on_plane = -plane.offset * plane.normal;
  // Offsets -4..5 mm (alternating side), camera distances 1..10 m.
  std::vector<Eigen::Vector3d> points;
  std::vector<double> distances;
  for (int i = 0; i < 10; ++i) {
    const double offset_m = (i % 2 == 0 ? 1 : -1) * (i + 1) * 1e-3;
    points.push_back(on_plane + 0.3 * i * u - 0.2 * i * v +
                     offset_m * plane.normal);
    distances.push_back(i + 1.0);
  }
  const PointAccuracy acc =
      EvaluatePointsAgainstPlane(points, distances, plane);
  EXPECT_EQ(acc.absolute_m.count, 10u);
  EXPECT_NEAR(acc.absolute_m.mean, 5.5e-3, 1e-12);
  EXPECT_NEAR(acc.absolute_m.median, 5.5e-3, 1e-12);
  EXPECT_NEAR(acc.absolute_m.p90, 9e-3, 1e-12);
  EXPECT_NEAR(acc.absolute_m.max, 10e-3, 1e-12);
  EXPECT_NEAR(acc.absolute_m.rms, std::sqrt(385.0 / 10.0) * 1e-3, 1e-12);
  // (i+1) mm at (i+1) m is 0.1 % for every point.
  EXPECT_NEAR(acc.relative_percent.mean, 0.1, 1e-9);
  EXPECT_NEAR(acc.relative_percent.max, 0.1, 1e-9);
  // 1..10 mm: none clearly above 1 cm; 9 and 10 mm above 8.5 mm.
  EXPECT_LE(acc.share_above_1cm, 0.1);
  EXPECT_EQ(ShareAbove({1e-3, 9e-3, 10e-3, 2e-3}, 8.5e-3), 0.5);
  EXPECT_EQ(ShareAbove({0.02, 0.005, 0.011}, 0.01), 2.0 / 3.0);
  EXPECT_EQ(ShareAbove({}, 0.01), 0.0);

  distances.pop_back();
  EXPECT_THROW(EvaluatePointsAgainstPlane(points, distances, plane),
               StageError);
  distances.push_back(0.0);
  EXPECT_THROW(EvaluatePointsAgainstPlane(points, distances, plane),
               StageError);
}

double BruteForce(const std::vector<Eigen::Vector3d>& cloud,
                  const Eigen::Vector3d& q) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& p : cloud) {
    const double dx = p.x() - q.x(), dy = p.y() - q.y(), dz = p.z() - q.z();
    best = std::min(best, dx * dx + dy * dy + dz * dz);
  }
  return std::sqrt(best);
}

void ExpectMatchesBruteForce(const std::vector<Eigen::Vector3d>& cloud,
                             const std::vector<Eigen::Vector3d>& queries) {
  const NearestNeighborIndex index(cloud);
  ASSERT_EQ(index.size(), cloud.size());
  const std::vector<double> batch = index.NearestDistances(queries);
  int mismatches = 0;
  for (size_t i = 0; i < queries.size(); ++i) {
    const double expected = BruteForce(cloud, queries[i]);
    size_t nn = cloud.size();
    const double d = index.NearestDistance(queries[i], &nn);
    ASSERT_LT(nn, cloud.size());
    const double via_index = (cloud[nn] - queries[i]).norm();
    mismatches += d != expected || batch[i] != expected ||
                  std::abs(via_index - expected) > 1e-12;
  }
  EXPECT_EQ(mismatches, 0);
}

std::vector<Eigen::Vector3d> RandomQueries(std::mt19937& rng, int n,
                                           double lo, double hi) {
  std::uniform_real_distribution<double> u(lo, hi);
  std::vector<Eigen::Vector3d> q(n);
  for (auto& x : q) x = DrawLastFirst<Eigen::Vector3d>(u, rng);
  return q;
}

TEST(NearestNeighborIndexTest, UniformCubeMatchesBruteForce) {
  std::mt19937 rng(1);
  const auto cloud = RandomQueries(rng, 20000, -1.0, 1.0);
  // Queries partly outside the cloud's box.
  ExpectMatchesBruteForce(cloud, RandomQueries(rng, 1000, -1.5, 1.5));
}

TEST(NearestNeighborIndexTest, SurfaceCloudMatchesBruteForce) {
  // A floor plane plus a sphere: a 2D manifold, like a surface scan.
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<Eigen::Vector3d> cloud;
  for (int i = 0; i < 30000; ++i) {
    const double y = u(rng);
    cloud.emplace_back(u(rng), y, 0.0);
  }
  for (int i = 0; i < 20000; ++i) {
    cloud.push_back(Eigen::Vector3d(0.5, 0.3, 1.0) +
                    0.7 * DrawLastFirst<Eigen::Vector3d>(g, rng).normalized());
  }
  ExpectMatchesBruteForce(cloud, RandomQueries(rng, 1000, -2.5, 2.5));
}

TEST(NearestNeighborIndexTest, ClusteredAndDegenerateClouds) {
  std::mt19937 rng(3);
  std::normal_distribution<double> g(0.0, 1.0);
  // Dense clusters far apart: most space is empty.
  std::vector<Eigen::Vector3d> clusters;
  for (int c = 0; c < 5; ++c) {
    const Eigen::Vector3d centre(10.0 * c, -5.0 * c, 2.0 * c);
    for (int i = 0; i < 2000; ++i) {
      clusters.push_back(centre +
                         0.01 * DrawLastFirst<Eigen::Vector3d>(g, rng));
    }
  }
  ExpectMatchesBruteForce(clusters, RandomQueries(rng, 1000, -5.0, 45.0));
  // Exactly planar cloud (one grid layer along z), with duplicate points.
  std::vector<Eigen::Vector3d> planar;
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < 5000; ++i) {
    const double y = u(rng);
    planar.emplace_back(u(rng), y, 0.0);
    if (i % 10 == 0) planar.push_back(planar.back());
  }
  ExpectMatchesBruteForce(planar, RandomQueries(rng, 1000, -0.5, 1.5));
  // A single point and far queries.
  const std::vector<Eigen::Vector3d> single = {Eigen::Vector3d(1, 2, 3)};
  ExpectMatchesBruteForce(single, RandomQueries(rng, 100, -1e6, 1e6));
  ExpectMatchesBruteForce(planar, {Eigen::Vector3d(1e7, -3e6, 5e5)});
}

TEST(NearestNeighborIndexTest, RejectsEmptyCloud) {
  EXPECT_THROW(NearestNeighborIndex(std::vector<Eigen::Vector3d>{}),
               StageError);
}

TEST(PointAccuracyTest, CloudDistancesOfPointsAboveAGrid) {
  // 1 cm grid on z = 0; points at known heights right above grid nodes.
  std::vector<Eigen::Vector3d> cloud;
  for (int i = 0; i <= 100; ++i) {
    for (int j = 0; j <= 100; ++j) cloud.emplace_back(0.01 * i, 0.01 * j, 0);
  }
  const NearestNeighborIndex index(cloud);
  std::vector<Eigen::Vector3d> points;
  std::vector<double> distances;
  for (int k = 1; k <= 4; ++k) {  // heights 1..4 mm, below half the spacing
    points.emplace_back(0.01 * (10 * k), 0.01 * (5 * k), 1e-3 * k);
    distances.push_back(2.0);
  }
  const PointAccuracy acc =
      EvaluatePointsAgainstCloud(points, distances, index);
  EXPECT_EQ(acc.absolute_m.count, 4u);
  EXPECT_NEAR(acc.absolute_m.mean, 2.5e-3, 1e-12);
  EXPECT_NEAR(acc.absolute_m.max, 4e-3, 1e-12);
  EXPECT_NEAR(acc.relative_percent.max, 0.2, 1e-9);
}

class PlaneYamlTest : public ::testing::Test {
 protected:
  std::filesystem::path Write(const std::string& text) {
    const auto path = std::filesystem::temp_directory_path() /
                      ("monomap_eval_plane_" +
                       std::to_string(reinterpret_cast<uintptr_t>(this)) +
                       ".yaml");
    std::ofstream(path) << text;
    paths_.push_back(path);
    return path;
  }
  void TearDown() override {
    for (const auto& p : paths_) std::filesystem::remove(p);
  }
  std::vector<std::filesystem::path> paths_;
};

TEST_F(PlaneYamlTest, ReadsAndNormalises) {
  Plane p = ReadGroundTruthPlaneYaml(
      Write("# desk\nplane: {normal: [0, 0, 1], offset: 0.0}\n"
            "chessboard: {square_m: 0.04}\n"));
  EXPECT_EQ(p.normal, Eigen::Vector3d::UnitZ());
  EXPECT_EQ(p.offset, 0.0);
  p = ReadGroundTruthPlaneYaml(
      Write("plane: {normal: [0, 3, 4], offset: -10}\n"));
  EXPECT_NEAR((p.normal - Eigen::Vector3d(0, 0.6, 0.8)).norm(), 0, 1e-15);
  EXPECT_DOUBLE_EQ(p.offset, -2.0);
}

TEST_F(PlaneYamlTest, ErrorsNameTheField) {
  auto expect_error = [&](const std::string& text, const std::string& field) {
    try {
      ReadGroundTruthPlaneYaml(Write(text));
      ADD_FAILURE() << "no error for: " << text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos)
          << e.what();
    }
  };
  expect_error("chessboard: {}\n", "plane");
  expect_error("plane: {normal: [0, 1], offset: 0}\n", "plane.normal");
  expect_error("plane: {normal: [0, a, 1], offset: 0}\n", "plane.normal");
  expect_error("plane: {normal: [0, 0, 0], offset: 0}\n", "plane.normal");
  expect_error("plane: {normal: [0, 0, 1]}\n", "plane.offset");
  expect_error("plane: {normal: [0, 0, 1], offset: [1]}\n", "plane.offset");
  expect_error("plane: {normal: [0, 0, 1\n", "malformed");
  EXPECT_THROW(ReadGroundTruthPlaneYaml("/nonexistent/structure.yaml"),
               InputError);
}

TEST(DistanceToTrajectoryTest, NearestCameraCentre) {
  std::vector<TimedPose> trajectory(2);
  trajectory[1].world_from_cam.translation = {2.0, 0.0, 0.0};
  const std::vector<double> d = DistanceToTrajectory(
      {{0.0, 3.0, 0.0}, {2.0, 0.0, 4.0}, {1.0, 0.0, 0.0}}, trajectory);
  ASSERT_EQ(d.size(), 3u);
  EXPECT_DOUBLE_EQ(d[0], 3.0);
  EXPECT_DOUBLE_EQ(d[1], 4.0);
  EXPECT_DOUBLE_EQ(d[2], 1.0);  // a tie: both centres 1 m away
  EXPECT_TRUE(std::isinf(DistanceToTrajectory({{0, 0, 0}}, {})[0]));
}

TEST(LandmarkSelectionTest, LargestPlaneAndPositions) {
  Map map;
  EXPECT_FALSE(LargestPlaneLabel(map).has_value());
  for (const int label : {-1, 2, 5, 5, 2, 7, -1, -1}) {
    Landmark l;
    l.plane_id = label;
    l.x_in_world = Eigen::Vector3d(map.landmarks.size(), 0, 0);
    map.landmarks.push_back(l);
  }
  // 2 and 5 have two points each: the lower label wins; -1 never counts.
  EXPECT_EQ(LargestPlaneLabel(map), 2);
  const std::vector<Eigen::Vector3d> on5 = LandmarkPositions(map, 5);
  ASSERT_EQ(on5.size(), 2u);
  EXPECT_EQ(on5[0].x(), 2.0);
  EXPECT_EQ(on5[1].x(), 3.0);
  EXPECT_EQ(LandmarkPositions(map, -1).size(), 3u);
  EXPECT_EQ(LandmarkPositions(map, kAllLandmarks).size(), 8u);
  EXPECT_TRUE(LandmarkPositions(map, 9).empty());
}

}  // namespace
}  // namespace monomap
