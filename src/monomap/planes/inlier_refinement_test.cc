#include "monomap/planes/inlier_refinement.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "monomap/util/error.h"
#include "monomap/util/stats.h"

namespace monomap {
namespace {

// A segment on z = height (normal +z), its frame at the origin.
PlaneSegment FloorSegment(int id, double height) {
  PlaneSegment seg;
  seg.id = id;
  seg.plane.normal = Eigen::Vector3d::UnitZ();
  seg.plane.offset = -height;
  seg.frame = MakePlaneFrame(seg.plane, Eigen::Vector3d::Zero(),
                             Eigen::Vector3d::UnitX());
  return seg;
}

// The covariance of a point seen along unit ray `ray` from a short
// baseline: loose (sigma_along) along the ray, tight across it.
Eigen::Matrix3d RayCovariance(const Eigen::Vector3d& ray, double sigma_along,
                              double sigma_across) {
  const Eigen::Matrix3d along = ray * ray.transpose();
  return sigma_along * sigma_along * along +
         sigma_across * sigma_across * (Eigen::Matrix3d::Identity() - along);
}

// A floor patch of `n` points over [0, 4] x [0, 4] on the surface
// z = height + bend(x), each displaced along its ray from a camera 1.2 m
// up and 2 m behind the patch by Gaussian noise of `sigma_along` (m),
// which is also what its covariance says.
struct Patch {
  std::vector<Landmark> landmarks;
  std::vector<Eigen::Vector3d> truth;
};

Patch MakePatch(int n, int plane_id, double height, double bend_amplitude,
                double sigma_along, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(0.0, 4.0);
  std::normal_distribution<double> noise(0.0, sigma_along);
  Patch patch;
  for (int i = 0; i < n; ++i) {
    const double x = uniform(rng), y = uniform(rng);
    const Eigen::Vector3d on_surface(
        x, y, height + bend_amplitude * (x / 4.0) * (x / 4.0));
    const Eigen::Vector3d camera(x, -2.0, 1.2);
    const Eigen::Vector3d ray = (on_surface - camera).normalized();
    Landmark l;
    l.id = static_cast<FeatureId>(plane_id * 100000 + i);
    l.plane_id = plane_id;
    l.x_in_world = on_surface + noise(rng) * ray;
    l.mean_depth_m = (on_surface - camera).norm();
    l.covariance_m2_per_px2 = RayCovariance(ray, sigma_along, 0.001);
    patch.landmarks.push_back(l);
    patch.truth.push_back(on_surface);
  }
  return patch;
}

// Median distance of the landmarks [first, first + count) to their true
// positions along z (the distance to the true surface there).
double MedianHeightError(const std::vector<Landmark>& landmarks,
                         const std::vector<Eigen::Vector3d>& truth,
                         size_t first = 0) {
  std::vector<double> e;
  for (size_t i = 0; i < truth.size(); ++i) {
    e.push_back(std::abs(landmarks[first + i].x_in_world.z() - truth[i].z()));
  }
  return Median(e);
}

TEST(InlierRefinement, NoisyInliersComeCloseToTheirPlaneAlongTheirRays) {
  Patch patch = MakePatch(800, 0, 0.0, 0.0, 0.02, 1);
  const std::vector<Landmark> before = patch.landmarks;
  const double error_before = MedianHeightError(before, patch.truth);
  const InlierRefinementReport report = RefineInliersOnPlanes(
      InlierRefinementOptions(), {FloorSegment(0, 0.0)}, &patch.landmarks);
  EXPECT_TRUE(report.enabled);
  EXPECT_EQ(report.num_moved, 800);
  const double error_after = MedianHeightError(patch.landmarks, patch.truth);
  // 50 neighbours' median: the noise shrinks by several times.
  EXPECT_LT(error_after, 0.25 * error_before)
      << error_before << " -> " << error_after;
  // Each point moved along its own ray, so it stays on it.
  for (size_t i = 0; i < before.size(); ++i) {
    const Eigen::Vector3d camera(patch.truth[i].x(), -2.0, 1.2);
    const Eigen::Vector3d ray = (patch.truth[i] - camera).normalized();
    const Eigen::Vector3d step =
        patch.landmarks[i].x_in_world - before[i].x_in_world;
    EXPECT_LT((step - step.dot(ray) * ray).norm(), 0.05 * step.norm() + 1e-9);
  }
  EXPECT_GT(report.median_move_m, 0.005);
}

TEST(InlierRefinement, ABendTheMapMeasuresIsKeptWhereOnePlaneWouldFlattenIt) {
  // 3 cm of bend across 4 m with 2 mm of noise: the map measures the bend.
  Patch patch = MakePatch(1500, 0, 0.0, 0.03, 0.002, 2);
  // The least-squares plane through a parabola's samples sits about a
  // third of the way up.
  const PlaneSegment segment = FloorSegment(0, 0.01);
  std::vector<Landmark> flattened = patch.landmarks;
  for (Landmark& l : flattened) {
    l.x_in_world = segment.plane.Project(l.x_in_world);
  }
  RefineInliersOnPlanes(InlierRefinementOptions(), {segment}, &patch.landmarks);
  const double local = MedianHeightError(patch.landmarks, patch.truth);
  const double global = MedianHeightError(flattened, patch.truth);
  EXPECT_LT(local, 0.3 * global) << local << " against " << global;
  EXPECT_LT(local, 0.0015);
}

TEST(InlierRefinement, EachPlaneUsesOnlyItsOwnInliersAndOutliersStay) {
  // A step 5 cm above the floor (another segment, as a keyboard on a
  // desk), fewer points than the neighbourhood, and an outlier.
  Patch floor = MakePatch(600, 0, 0.0, 0.0, 0.01, 3);
  Patch step = MakePatch(30, 1, 0.05, 0.0, 0.01, 4);
  std::vector<Landmark> landmarks = floor.landmarks;
  landmarks.insert(landmarks.end(), step.landmarks.begin(),
                   step.landmarks.end());
  Landmark outlier;
  outlier.x_in_world = {1.0, 1.0, 0.2};
  outlier.plane_id = -1;
  landmarks.push_back(outlier);
  const double step_before =
      MedianHeightError(landmarks, step.truth, floor.truth.size());
  const InlierRefinementReport report = RefineInliersOnPlanes(
      InlierRefinementOptions(), {FloorSegment(0, 0.0), FloorSegment(1, 0.05)},
      &landmarks);
  EXPECT_EQ(report.num_moved, 630);
  // The step's points settle on the step, not on the floor below.
  const double step_after =
      MedianHeightError(landmarks, step.truth, floor.truth.size());
  EXPECT_LT(step_after, 0.5 * step_before)
      << step_before << " -> " << step_after;
  EXPECT_EQ(landmarks.back().x_in_world, outlier.x_in_world);
}

TEST(InlierRefinement, DisabledKeepsTheTriangulatedPositions) {
  Patch patch = MakePatch(100, 0, 0.0, 0.0, 0.02, 5);
  const std::vector<Landmark> before = patch.landmarks;
  InlierRefinementOptions options;
  options.enabled = false;
  const InlierRefinementReport report =
      RefineInliersOnPlanes(options, {FloorSegment(0, 0.0)}, &patch.landmarks);
  EXPECT_FALSE(report.enabled);
  EXPECT_EQ(report.num_moved, 0);
  for (size_t i = 0; i < before.size(); ++i) {
    EXPECT_EQ(patch.landmarks[i].x_in_world, before[i].x_in_world);
  }
  options.enabled = true;
  options.neighbours = 0;
  EXPECT_THROW(
      RefineInliersOnPlanes(options, {FloorSegment(0, 0.0)}, &patch.landmarks),
      OptionsError);
}

}  // namespace
}  // namespace monomap
