// The mapping pipeline end to end on simulated worlds with exact ground
// truth, compared with the true planes by EvaluateStructure (eval/):
// accuracy figures, not just that it ran. Each fixture prints its figures
// (run the test binary to see them).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "monomap/eval/report_json.h"
#include "monomap/eval/structure_accuracy.h"
#include "monomap/io/dataset.h"
#include "monomap/io/map_format.h"
#include "monomap/pipelines/mapping_pipeline.h"
#include "monomap/sim/simulate.h"
#include "monomap/util/progress.h"
#include "nav_grid_truth.h"

namespace monomap {
namespace {
namespace fs = std::filesystem;

// A simulated world, its map and the map's accuracy.
struct MappedWorld {
  fs::path dir;
  MappingResult result;
  Map truth;
  StructureAccuracy accuracy;
  double simulate_seconds = 0.0;
  double mapping_seconds = 0.0;
};

// Simulates, maps from images and odometry only (the ground truth is
// stripped) and evaluates without alignment: the simulator's odometry
// starts at the true pose, so the map is in the truth's frame.
std::unique_ptr<MappedWorld> SimulateAndMap(const SimulationOptions& sim,
                                            const std::string& name) {
  auto w = std::make_unique<MappedWorld>();
  w->dir = fs::temp_directory_path() /
           ("monomap_e2e_" + name + "_" + std::to_string(getpid()));
  const Timer sim_timer;
  Simulate(sim, w->dir);
  w->simulate_seconds = sim_timer.ElapsedSeconds();
  Dataset dataset = LoadDataset(w->dir);
  dataset.has_groundtruth = false;
  for (auto& f : dataset.frames) f.groundtruth_world_from_cam.reset();
  const Timer mapping_timer;
  w->result = BuildMap(dataset, MappingOptions{});
  w->mapping_seconds = mapping_timer.ElapsedSeconds();
  w->truth = ReadMap(w->dir / "structure");
  w->accuracy = EvaluateStructure(w->result.map, w->truth, Rigid3d::Identity(),
                                  StructureAccuracyOptions{});
  std::printf("%s: simulate %.1f s, map %.1f s\n%s", name.c_str(),
              w->simulate_seconds, w->mapping_seconds,
              FormatTable(w->accuracy).c_str());
  return w;
}

// The result for the true plane with this normal and offset (either
// orientation), or nullptr.
const TruePlaneResult* FindTruePlane(const MappedWorld& w,
                                     const Eigen::Vector3d& normal,
                                     double offset) {
  for (size_t j = 0; j < w.truth.planes.size(); ++j) {
    const Plane& p = w.truth.planes[j].plane;
    const double sign = p.normal.dot(normal) < 0 ? -1.0 : 1.0;
    if ((sign * p.normal - normal).norm() < 1e-9 &&
        std::abs(sign * p.offset - offset) < 1e-9) {
      return &w.accuracy.true_plane_results[j];
    }
  }
  return nullptr;
}

// Lab corner at 320x240, 120 frames. The camera drives towards the walls:
// little parallax on them, so only the floor is expected as a plane.
SimulationOptions LabCorner() {
  SimulationOptions sim;
  sim.world = "lab-corner";
  sim.seed = 3;
  sim.num_frames = 120;
  sim.width = 320;
  sim.height = 240;
  // Scale drift of the odometry is unobservable from one camera, so the
  // map inherits it; a well-calibrated robot (0.3% systematic error)
  // keeps the 1% accuracy target meaningful.
  sim.odometry.wheel_radius_error = 0.003;
  sim.odometry.yaw_scale_error = 0.003;
  return sim;
}

class MappingE2E : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    world_ = SimulateAndMap(LabCorner(), "lab_corner").release();
  }
  static void TearDownTestSuite() {
    fs::remove_all(world_->dir);
    delete world_;
  }
  static MappedWorld* world_;
};
MappedWorld* MappingE2E::world_ = nullptr;

TEST_F(MappingE2E, PointsLieOnTheTrueStructure) {
  const StructureAccuracy& a = world_->accuracy;
  ASSERT_GT(a.landmarks, 300);
  EXPECT_LT(a.landmarks_off_structure, 0.1 * a.landmarks);
  // Median of all landmarks, planes or not. Measured 1.7% at 320x240: depth
  // from a forward-moving camera at low resolution is poorly conditioned.
  // The project target is 1%; this guards against regressions until it is
  // met.
  EXPECT_LT(a.point_error_all.relative_percent.median, 2.0);
}

TEST_F(MappingE2E, BundleAdjustmentReducesReprojectionError) {
  const auto& ba = world_->result.report.bundle_adjustment;
  EXPECT_LT(ba.final_median_error_px, 0.7 * ba.initial_median_error_px);
  // Points triangulated again against the adjusted poses fit well.
  EXPECT_LT(world_->result.report.retriangulation.mean_reprojection_error_px,
            1.0);
}

TEST_F(MappingE2E, EveryFittedPlaneMatchesATruePlane) {
  const StructureAccuracy& a = world_->accuracy;
  ASSERT_GE(a.fitted_planes, 1);
  EXPECT_EQ(a.precision, 1.0);
  for (const PlaneMatch& m : a.matches) {
    EXPECT_TRUE(m.matched) << "fitted plane " << m.fitted_id << ": true plane "
                           << m.true_id << ", " << m.normal_error_deg
                           << " deg, " << m.offset_error_m * 1000 << " mm";
  }
}

TEST_F(MappingE2E, FloorIsFoundWithinOneDegree) {
  const TruePlaneResult* floor =
      FindTruePlane(*world_, Eigen::Vector3d::UnitZ(), 0.0);
  ASSERT_NE(floor, nullptr) << "no floor (z = 0) in the structure";
  EXPECT_TRUE(floor->observed);
  EXPECT_TRUE(floor->matched);
  EXPECT_LT(floor->normal_error_deg, 1.0)
      << "best fitted plane " << floor->best_fitted_id;
}

// Hallway at 640x480, 150 frames (seed 1, as the demo): every wall the
// camera sees well enough is a plane. Odometry errors as the lab corner:
// with the simulator's default 1% scale error the walls sit ~1.6% off
// their true offset, because the map inherits the odometry's scale.
class MappingE2EHallway : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    SimulationOptions sim;
    sim.world = "hallway";
    sim.seed = 1;
    sim.num_frames = 150;
    sim.width = 640;
    sim.height = 480;
    sim.odometry.wheel_radius_error = 0.003;
    sim.odometry.yaw_scale_error = 0.003;
    world_ = SimulateAndMap(sim, "hallway").release();
  }
  static void TearDownTestSuite() {
    fs::remove_all(world_->dir);
    delete world_;
  }
  static MappedWorld* world_;
};
MappedWorld* MappingE2EHallway::world_ = nullptr;

TEST_F(MappingE2EHallway, EveryObservedTruePlaneIsFoundAndNoOther) {
  const StructureAccuracy& a = world_->accuracy;
  ASSERT_GE(a.observed_true_planes, 1);
  EXPECT_EQ(a.recall, 1.0);
  EXPECT_EQ(a.precision, 1.0);
  for (const PlaneMatch& m : a.matches) {
    EXPECT_TRUE(m.matched) << "fitted plane " << m.fitted_id << ": true plane "
                           << m.true_id << ", " << m.normal_error_deg
                           << " deg, " << m.offset_error_m * 1000 << " mm";
  }
}

// Matching (normal and offset) is the test above; this one is about the
// normal of each observed true plane's best fitted plane.
TEST_F(MappingE2EHallway, ObservedTruePlanesWithinOneDegree) {
  for (const TruePlaneResult& t : world_->accuracy.true_plane_results) {
    if (!t.observed) continue;
    ASSERT_GE(t.best_fitted_id, 0) << "true plane " << t.true_id;
    EXPECT_LT(t.normal_error_deg, 1.0)
        << "true plane " << t.true_id << ", best fitted plane "
        << t.best_fitted_id;
  }
}

TEST_F(MappingE2EHallway, PointsOnPlanesWithinOnePercentOfDepth) {
  const PointAccuracy& p = world_->accuracy.point_error_on_planes;
  ASSERT_GT(p.relative_percent.count, 300u);
  EXPECT_LT(p.relative_percent.median, 1.0);
}

// The navigation grid of the built hallway map (0.1 m cells) against the
// true walls: the walls it shows lie on the true ones (the map inherits
// the odometry's ~1.6% scale error, a few centimetres here).
TEST_F(MappingE2EHallway, NavGridWallsLieOnTheTrueWalls) {
  NavGridOptions options;
  options.resolution_m = 0.1;
  NavGridReport report;
  const NavGrid grid = MakeNavGrid(world_->result.map, options, &report);
  const NavGridFigures f =
      MeasureNavGrid(grid, NavGridTruth(world_->truth.planes, options));
  std::printf(
      "hallway nav grid: %d occupied cells (%d obstacle planes), %.1f%% "
      "within one cell of a true wall (max %.2f cells), %.1f%% of the true "
      "wall length covered, %.1f%% of the interior floor free, %.2f%% of "
      "free cells off the floor\n",
      report.num_occupied, report.num_obstacle_planes,
      100 * f.occupied_within_one_cell, f.max_wall_cell_distance_cells,
      100 * f.wall_length_covered, 100 * f.interior_floor_free,
      100 * f.free_outside_floor);
  // Measured (seed 1): 70 occupied cells from the 2 side walls, all within
  // 0.5 cell; 31% of the true wall length (the walls are planes only where
  // the camera saw them with parallax), 42% of the floor free (the floor
  // plane's extent is the hull of its points).
  EXPECT_GT(report.num_occupied, 40);
  EXPECT_LE(f.max_wall_cell_distance_cells, 1.0);
  EXPECT_GE(f.wall_length_covered, 0.25);
  EXPECT_GE(f.interior_floor_free, 0.35);
  EXPECT_LE(f.free_outside_floor, 0.01);
}

// The lab corner seen through a fisheye (equidistant) lens: 320x240 with
// 122 degrees of horizontal field of view. Tracking, triangulation, bundle
// adjustment and texturing all go through the camera's own model, so the
// map is as good as with the plumb_bob lens above.
TEST(MappingE2EFisheye, LabCornerThroughAnEquidistantLens) {
  SimulationOptions sim = LabCorner();
  sim.lens = "equidistant";
  sim.focal_px_at_640 = 300.0;
  sim.k1 = 0.02;
  sim.k2 = -0.004;
  const auto w = SimulateAndMap(sim, "lab_corner_fisheye");
  // Measured: floor normal 0.26 deg (plumb_bob lens above: 0.16), median
  // depth error 0.60% (0.39%), on the floor 0.37% (0.23%): the fisheye
  // has 40% fewer pixels per degree.
  EXPECT_EQ(w->result.map.camera.model, LensModel::kEquidistant);
  EXPECT_EQ(ReadMap(w->dir / "structure").camera.model,
            LensModel::kEquidistant);
  const StructureAccuracy& a = w->accuracy;
  EXPECT_GT(a.landmarks, 300);
  EXPECT_LT(a.landmarks_off_structure, 0.1 * a.landmarks);
  EXPECT_LT(a.point_error_all.relative_percent.median, 2.0);
  const auto& ba = w->result.report.bundle_adjustment;
  EXPECT_LT(ba.final_median_error_px, 0.7 * ba.initial_median_error_px);
  const TruePlaneResult* floor =
      FindTruePlane(*w, Eigen::Vector3d::UnitZ(), 0.0);
  ASSERT_NE(floor, nullptr);
  EXPECT_TRUE(floor->matched);
  EXPECT_LT(floor->normal_error_deg, 1.0);
  EXPECT_EQ(a.precision, 1.0);
  fs::remove_all(w->dir);
}

}  // namespace
}  // namespace monomap
