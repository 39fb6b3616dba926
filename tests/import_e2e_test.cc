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
#include "tests/import_check.h"
#include "tests/monomap_cli.h"

namespace monomap {
namespace {
namespace fs = std::filesystem;
using namespace rosbag_test;
using test::RunMonomap;
using test::RunResult;

const fs::path kRoot = fs::temp_directory_path() /
                       ("monomap_import_e2e_" + std::to_string(getpid()));

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

Dataset SimulateHallway() {
  fs::remove_all(kRoot);
  return test::SimulateHallway(kRoot / "sim");
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

  test::ExpectSameDataset(sim, LoadDataset(kRoot / "imported"));
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
