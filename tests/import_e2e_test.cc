// Round trips through the importers: a simulated run written into a ROS 1
// bag and imported back must give the same dataset (poses within 1e-6,
// identical pixels); the `monomap import` command's exit codes and errors.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "monomap/io/dataset.h"
#include "monomap/io/rosbag_import.h"
#include "monomap/io/rosbag_test_bag.h"
#include "monomap/sim/simulate.h"
#include "tests/monomap_cli.h"

namespace monomap {
namespace {
namespace fs = std::filesystem;
using namespace rosbag_test;
using test::RunMonomap;
using test::RunResult;

const fs::path kRoot = fs::temp_directory_path() /
                       ("monomap_import_e2e_" + std::to_string(getpid()));

double PoseError(const Rigid3d& a, const Rigid3d& b) {
  return (a.translation - b.translation).norm() +
         AngleBetween(a.rotation, b.rotation);
}

// Writes the simulated dataset as a robot would have logged it: images,
// camera_info, nav_msgs/Odometry of the base, /tf_static base -> camera.
fs::path WriteBagOf(const Dataset& sim) {
  const fs::path path = kRoot / "hallway.bag";
  rosbag::Bag bag(path.string(), rosbag::bagmode::Write);
  const double t0 = sim.frames.front().timestamp;
  bag.write("/camera/camera_info", ros::Time(t0),
            CameraInfoMsg(sim.camera, "camera_optical", t0));
  bag.write("/tf_static", ros::Time(t0),
            TfMsg(*sim.base_from_cam, "base_footprint", "camera_optical", t0));
  for (size_t i = 0; i < sim.frames.size(); ++i) {
    const DatasetFrame& f = sim.frames[i];
    const Pose2d& b = *f.odometry_base;
    const Rigid3d odom_from_base(YawRotation(b.yaw),
                                 Eigen::Vector3d(b.x, b.y, 0.0));
    bag.write(
        "/odom", ros::Time(f.timestamp),
        OdometryMsg(odom_from_base, "odom", "base_footprint", f.timestamp));
    const cv::Mat image = sim.LoadImage(i, /*color=*/true);
    bag.write("/camera/image_raw", ros::Time(f.timestamp),
              ImageMsg(image, "bgr8", "camera_optical", f.timestamp));
  }
  bag.close();
  return path;
}

// A short simulated hallway run (25 frames, 160x120) in kRoot/sim.
Dataset SimulateHallway() {
  fs::remove_all(kRoot);
  SimulationOptions so;
  so.world = "hallway";
  so.num_frames = 25;
  so.width = 160;
  so.height = 120;
  so.write_structure = false;
  Simulate(so, kRoot / "sim");
  DatasetOptions no_gt;
  no_gt.load_groundtruth = false;
  return LoadDataset(kRoot / "sim", no_gt);
}

TEST(ImportE2e, SimulatedHallwayRoundTripsThroughARosbag) {
  const Dataset sim = SimulateHallway();
  ASSERT_TRUE(sim.base_from_cam.has_value());

  RosbagImportOptions o;
  o.image_topic = "/camera/image_raw";
  o.camera_info_topic = "/camera/camera_info";
  o.odom_topic = "/odom";
  const RosbagImportReport r =
      ImportRosbag(WriteBagOf(sim), kRoot / "imported", o);
  EXPECT_EQ(r.frames_written, 25);
  EXPECT_EQ(r.dropped_outside_odometry + r.dropped_in_gap, 0);
  EXPECT_TRUE(r.planar);

  const Dataset imported = LoadDataset(kRoot / "imported");
  ASSERT_EQ(imported.frames.size(), sim.frames.size());
  EXPECT_LT(PoseError(*imported.base_from_cam, *sim.base_from_cam), 1e-9);
  EXPECT_EQ(imported.camera.width, sim.camera.width);
  EXPECT_NEAR(imported.camera.fx, sim.camera.fx, 1e-9);
  EXPECT_NEAR(imported.camera.distortion[0], sim.camera.distortion[0], 1e-9);
  double max_pose = 0, max_base = 0, max_dt = 0, max_pixel = 0;
  for (size_t i = 0; i < sim.frames.size(); ++i) {
    const DatasetFrame& a = sim.frames[i];
    const DatasetFrame& b = imported.frames[i];
    max_dt = std::max(max_dt, std::abs(a.timestamp - b.timestamp));
    max_pose = std::max(max_pose, PoseError(a.odometry_world_from_cam,
                                            b.odometry_world_from_cam));
    max_base = std::max(
        max_base,
        std::abs(a.odometry_base->x - b.odometry_base->x) +
            std::abs(a.odometry_base->y - b.odometry_base->y) +
            std::abs(std::remainder(a.odometry_base->yaw - b.odometry_base->yaw,
                                    2 * M_PI)));
    cv::Mat diff;
    cv::absdiff(sim.LoadImage(i, true), imported.LoadImage(i, true), diff);
    double worst = 0;
    cv::minMaxLoc(diff.reshape(1), nullptr, &worst);
    max_pixel = std::max(max_pixel, worst);
  }
  EXPECT_LT(max_dt, 1e-6);
  EXPECT_LT(max_pose, 1e-6);
  EXPECT_LT(max_base, 1e-6);
  EXPECT_EQ(max_pixel, 0.0);
  fs::remove_all(kRoot);
}


TEST(ImportE2e, CommandReportsAndFails) {
  const fs::path bag = WriteBagOf(SimulateHallway());
  RunResult r = RunMonomap("import rosbag " + bag.string() + " -o " +
                           (kRoot / "cli").string() +
                           " --image-topic /camera/image_raw"
                           " --camera-info-topic /camera/camera_info"
                           " --odom-topic /odom");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("25 of 25 images imported (bgr8), 0 dropped"),
            std::string::npos)
      << r.output;
  r = RunMonomap("import rosbag " + bag.string() + " -o " +
                 (kRoot / "cli2").string() +
                 " --image-topic /cam/image --camera-info-topic "
                 "/camera/camera_info --odom-topic /odom");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("no topic '/cam/image' in the bag; it has: "
                          "/camera/camera_info"),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(kRoot / "cli2"));
  fs::remove_all(kRoot);
}

}  // namespace
}  // namespace monomap
