#include "monomap/sim/simulate.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "monomap/io/dataset.h"
#include "monomap/io/map_format.h"
#include "monomap/util/error.h"
#include "monomap/util/file.h"

namespace monomap {
namespace {

namespace fs = std::filesystem;

fs::path TempDir(const std::string& name) {
  const fs::path p = fs::temp_directory_path() /
                     ("monomap_sim_test_" + name + "_" +
                      std::to_string(::testing::UnitTest::GetInstance()
                                         ->random_seed()));
  fs::remove_all(p);
  return p;
}

SimulationOptions SmallOptions() {
  SimulationOptions o;
  o.world = "room";
  o.num_frames = 12;
  o.width = 160;
  o.height = 120;
  o.texture_pixels_per_meter = 60;
  o.write_structure = false;
  return o;
}

std::map<std::string, std::string> ReadTree(const fs::path& root) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(root)) {
    if (e.is_regular_file()) {
      files[fs::relative(e.path(), root).string()] =
          ReadFileToString(e.path());
    }
  }
  return files;
}

TEST(SimulateTest, DatasetLoadsWithGroundTruthAndStructure) {
  const fs::path dir = TempDir("load");
  SimulationOptions o = SmallOptions();
  o.write_structure = true;
  const SimulationReport report = Simulate(o, dir);
  EXPECT_EQ(report.frames, 12);
  EXPECT_GT(report.planes, 10);
  EXPECT_NEAR(report.path_length_m, 11 * 0.4 / 30, 0.01);
  const Dataset ds = LoadDataset(dir);
  ASSERT_EQ(ds.frames.size(), 12u);
  EXPECT_TRUE(ds.has_groundtruth);
  ASSERT_TRUE(ds.base_from_cam.has_value());
  EXPECT_EQ(ds.camera.width, 160);
  EXPECT_NEAR(ds.camera.fx, 125.0, 1e-9);
  EXPECT_NEAR(ds.camera.distortion[0], -0.25, 1e-12);
  for (size_t i = 0; i < ds.frames.size(); ++i) {
    const DatasetFrame& f = ds.frames[i];
    ASSERT_TRUE(f.groundtruth_world_from_cam.has_value());
    ASSERT_TRUE(f.odometry_base.has_value());
    // odometry.txt and odometry2d.txt + mount agree.
    const Rigid3d from2d = WorldFromCamOfBase(*f.odometry_base,
                                              *ds.base_from_cam);
    EXPECT_LT((from2d.translation - f.odometry_world_from_cam.translation)
                  .norm(), 1e-6);
    // The camera is at the mount height above the floor.
    EXPECT_NEAR(f.groundtruth_world_from_cam->translation.z(),
                o.mount.height_m, 1e-6);
  }
  // Odometry is anchored at the true start.
  EXPECT_LT((ds.frames[0].odometry_world_from_cam.translation -
             ds.frames[0].groundtruth_world_from_cam->translation).norm(),
            1e-6);
  const cv::Mat img = ds.LoadImage(3);
  EXPECT_EQ(img.type(), CV_8UC1);
  cv::Scalar mean, stddev;
  cv::meanStdDev(img, mean, stddev);
  EXPECT_GT(stddev[0], 10.0);  // textured, not blank
  // The structure is a readable map with the world's planes.
  const Map structure = ReadMap(dir / "structure");
  EXPECT_EQ(static_cast<int>(structure.planes.size()), report.planes);
  EXPECT_EQ(structure.trajectory.size(), 12u);
  fs::remove_all(dir);
}

TEST(SimulateTest, GroundTruthPosesReproduceTheImages) {
  const fs::path dir = TempDir("gt");
  SimulationOptions o = SmallOptions();
  o.effects = CameraEffectsOptions::None();
  Simulate(o, dir);
  const Dataset ds = LoadDataset(dir);
  // Re-render frame 7 from the world and the pose read back from
  // groundtruth.txt: the saved image must match it.
  const World world = MakeWorld(o.world, o.seed, o.texture_pixels_per_meter);
  SceneRenderer renderer(ds.camera, o.render);
  for (const TexturedPlane& p : world.planes) renderer.AddPlane(p);
  const Rigid3d pose = *ds.frames[7].groundtruth_world_from_cam;
  auto render = [&](const Rigid3d& pose) {
    return ApplyCameraEffects(renderer.Render(pose), 0.0, o.effects, 0, 0);
  };
  const cv::Mat saved = ds.LoadImage(7);
  cv::Mat diff;
  cv::absdiff(saved, render(pose), diff);
  EXPECT_LT(cv::mean(diff)[0], 0.05);
  // A 1 cm pose error is clearly visible: the check is sensitive.
  Rigid3d moved = pose;
  moved.translation.x() += 0.01;
  cv::absdiff(saved, render(moved), diff);
  EXPECT_GT(cv::mean(diff)[0], 1.0);
  fs::remove_all(dir);
}

TEST(SimulateTest, DeterministicForASeed) {
  const fs::path a = TempDir("det_a"), b = TempDir("det_b"),
                 c = TempDir("det_c");
  SimulationOptions o = SmallOptions();
  o.num_frames = 5;
  o.write_structure = true;
  o.specular_highlight = true;
  Simulate(o, a);
  Simulate(o, b);
  o.seed = 2;
  Simulate(o, c);
  const auto fa = ReadTree(a), fb = ReadTree(b), fc = ReadTree(c);
  ASSERT_EQ(fa.size(), fb.size());
  EXPECT_GT(fa.size(), 10u);
  for (const auto& [name, bytes] : fa) {
    ASSERT_TRUE(fb.count(name)) << name;
    EXPECT_TRUE(bytes == fb.at(name)) << name << " differs";
  }
  EXPECT_NE(fa.at("rgb/000000.png"), fc.at("rgb/000000.png"));
  EXPECT_NE(fa.at("odometry2d.txt"), fc.at("odometry2d.txt"));
  for (const auto& p : {a, b, c}) fs::remove_all(p);
}

TEST(SimulateTest, RunSeedChangesTheRunButNotTheWorld) {
  const fs::path a = TempDir("run_a"), b = TempDir("run_b"),
                 c = TempDir("run_c");
  SimulationOptions o = SmallOptions();
  o.num_frames = 4;
  o.seed = 3;
  Simulate(o, a);
  o.run_seed = 3;  // the same as run_seed 0
  Simulate(o, b);
  o.run_seed = 11;
  Simulate(o, c);
  const auto fa = ReadTree(a), fb = ReadTree(b), fc = ReadTree(c);
  ASSERT_EQ(fa.size(), fb.size());
  for (const auto& [name, bytes] : fa) {
    EXPECT_TRUE(bytes == fb.at(name)) << name << " differs";
  }
  // Another run: other odometry errors and image noise, same path.
  EXPECT_NE(fa.at("odometry2d.txt"), fc.at("odometry2d.txt"));
  EXPECT_NE(fa.at("rgb/000002.png"), fc.at("rgb/000002.png"));
  EXPECT_EQ(fa.at("groundtruth.txt"), fc.at("groundtruth.txt"));
  // Same world: without camera effects the images are identical.
  const fs::path d = TempDir("run_d"), e = TempDir("run_e");
  o.effects = CameraEffectsOptions::None();
  o.run_seed = 0;
  Simulate(o, d);
  o.run_seed = 11;
  Simulate(o, e);
  const auto fd = ReadTree(d), fe = ReadTree(e);
  EXPECT_EQ(fd.at("rgb/000002.png"), fe.at("rgb/000002.png"));
  for (const auto& p : {a, b, c, d, e}) fs::remove_all(p);
}

TEST(SimulateTest, PathOffsetsMoveTheRun) {
  const fs::path dir = TempDir("offsets");
  SimulationOptions o = SmallOptions();
  o.world = "hallway";
  o.num_frames = 3;
  o.path.start_offset_m = 1.0;
  o.path.lateral_offset_m = 0.2;
  Simulate(o, dir);
  const Dataset ds = LoadDataset(dir);
  const World world = MakeWorld(o.world, o.seed, o.texture_pixels_per_meter);
  const Pose2d s = RobotPath(world).PoseAt(1.0);
  const Pose2d start{s.x - 0.2 * std::sin(s.yaw), s.y + 0.2 * std::cos(s.yaw),
                     s.yaw};
  const Rigid3d expected = WorldFromCamOfBase(start, *ds.base_from_cam);
  EXPECT_LT((ds.frames[0].groundtruth_world_from_cam->translation -
             expected.translation).norm(), 1e-6);
  // Odometry is anchored at the run's true start.
  EXPECT_NEAR(ds.frames[0].odometry_base->x, start.x, 1e-6);
  EXPECT_NEAR(ds.frames[0].odometry_base->y, start.y, 1e-6);
  fs::remove_all(dir);
}

TEST(SimulateTest, DriftIsReportedAndZeroWithoutNoise) {
  const fs::path dir = TempDir("drift");
  SimulationOptions o = SmallOptions();
  o.world = "hallway";
  o.num_frames = 3;
  o.odometry = OdometryNoiseOptions::None();
  SimulationReport r = Simulate(o, dir);
  EXPECT_LT(r.final_drift_m, 1e-9);
  const Dataset ds = LoadDataset(dir);
  for (const DatasetFrame& f : ds.frames) {
    EXPECT_LT((f.odometry_world_from_cam.translation -
               f.groundtruth_world_from_cam->translation).norm(), 1e-6);
  }
  fs::remove_all(dir);
}

// Base tilt (degrees) of a camera pose: the angle between the base's up
// axis and the world's.
double BaseTiltDeg(const Rigid3d& world_from_cam,
                   const Rigid3d& base_from_cam) {
  const Rigid3d world_from_base = world_from_cam * base_from_cam.Inverse();
  const Eigen::Vector3d up =
      world_from_base.rotation * Eigen::Vector3d::UnitZ();
  return std::acos(std::min(1.0, up.z())) * 180.0 / M_PI;
}

TEST(SimulateTest, UnevenFloorTiltsTheTruthNotTheOdometry) {
  const fs::path dir = TempDir("tilt");
  SimulationOptions o = SmallOptions();
  o.num_frames = 60;
  o.floor_tilt_deg = 0.5;
  Simulate(o, dir);
  const Dataset ds = LoadDataset(dir);
  ASSERT_TRUE(ds.base_from_cam.has_value());
  double max_true = 0.0, max_odometry = 0.0, max_height = 0.0;
  for (const DatasetFrame& f : ds.frames) {
    max_true = std::max(max_true, BaseTiltDeg(*f.groundtruth_world_from_cam,
                                              *ds.base_from_cam));
    max_odometry = std::max(max_odometry, BaseTiltDeg(f.odometry_world_from_cam,
                                                      *ds.base_from_cam));
    const Rigid3d base =
        *f.groundtruth_world_from_cam * ds.base_from_cam->Inverse();
    max_height = std::max(max_height, std::abs(base.translation.z()));
  }
  // Two sinusoids of 0.6 and 0.4 x 0.5 deg per axis: at most ~0.7 deg.
  EXPECT_GT(max_true, 0.1);
  EXPECT_LT(max_true, 0.75);
  EXPECT_LT(max_odometry, 1e-6);
  EXPECT_LT(max_height, 1e-9);  // tilted about the base's origin
  o.floor_tilt_deg = -1.0;
  EXPECT_THROW(o.Check(), OptionsError);
  fs::remove_all(dir);
}

TEST(SimulateTest, MovingObjectChangesOnlyItsFrames) {
  const fs::path with = TempDir("obj_on"), without = TempDir("obj_off");
  SimulationOptions o = SmallOptions();
  o.world = "hallway";
  o.num_frames = 15;
  Simulate(o, without);
  o.moving_object = true;
  const SimulationReport r = Simulate(o, with);
  ASSERT_EQ(r.moving_object_first_frame, 6);
  ASSERT_EQ(r.moving_object_last_frame, 8);
  for (int i = 0; i < 15; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "rgb/%06d.png", i);
    const cv::Mat a = cv::imread((with / name).string(), cv::IMREAD_UNCHANGED);
    const cv::Mat b =
        cv::imread((without / name).string(), cv::IMREAD_UNCHANGED);
    cv::Mat diff;
    cv::absdiff(a, b, diff);
    const int changed = cv::countNonZero(diff > 10);
    if (i >= 6 && i <= 8) {
      EXPECT_GT(changed, 100) << "frame " << i;
    } else {
      EXPECT_EQ(cv::countNonZero(diff), 0) << "frame " << i;
    }
  }
  fs::remove_all(with);
  fs::remove_all(without);
}

TEST(SimulateTest, BadOptionsLeaveNothing) {
  const fs::path dir = TempDir("bad");
  SimulationOptions o = SmallOptions();
  o.world = "garage";
  EXPECT_THROW(Simulate(o, dir), OptionsError);
  o = SmallOptions();
  o.num_frames = 0;
  EXPECT_THROW(Simulate(o, dir), OptionsError);
  EXPECT_FALSE(fs::exists(dir));
}

}  // namespace
}  // namespace monomap
