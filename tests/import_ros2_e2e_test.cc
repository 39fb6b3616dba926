// `monomap import rosbag` on a ROS 2 bag directory: a simulated run logged
// into a ROS 2 bag (sqlite3 + CDR) must import to the same dataset; bad
// bags fail with exit code 1, a message naming the file and topic or
// field, and no output.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "monomap/io/dataset.h"
#include "monomap/io/rosbag2_test_bag.h"
#include "tests/import_check.h"
#include "tests/monomap_cli.h"

namespace monomap {
namespace {
namespace fs = std::filesystem;
using test::RunMonomap;
using test::RunResult;

const fs::path kRoot = fs::temp_directory_path() /
                       ("monomap_import_ros2_e2e_" + std::to_string(getpid()));
struct RemoveAtExit {
  ~RemoveAtExit() {
    std::error_code ec;
    fs::remove_all(kRoot, ec);
  }
} remove_at_exit;

// The simulated run as a robot running ROS 2 would have logged it.
fs::path WriteRos2BagOf(const Dataset& sim, const std::string& storage) {
  const fs::path dir = kRoot / ("hallway_" + storage);
  rosbag2_test::Ros2BagWriter bag(dir);
  const double t0 = sim.frames.front().timestamp;
  bag.CameraInfo("/camera/camera_info", t0, sim.camera,
                 LensModelName(sim.camera.model), true);
  bag.Tf("/tf_static", t0, 0.0, "base_footprint", "camera_optical",
         *sim.base_from_cam);
  for (size_t i = 0; i < sim.frames.size(); ++i) {
    const DatasetFrame& f = sim.frames[i];
    const Pose2d& b = *f.odometry_base;
    bag.Odometry("/odom", f.timestamp, "odom", "base_footprint",
                 Rigid3d(YawRotation(b.yaw), Eigen::Vector3d(b.x, b.y, 0.0)));
    bag.Image("/camera/image_raw", f.timestamp, "camera_optical",
              sim.LoadImage(i, /*color=*/true), "bgr8");
  }
  bag.Close(storage);
  return dir;
}

const char kTopics[] =
    " --image-topic /camera/image_raw --camera-info-topic "
    "/camera/camera_info --odom-topic /odom";

TEST(ImportRos2E2e, SimulatedHallwayRoundTripsThroughTheCommand) {
  const Dataset sim = test::SimulateHallway(kRoot / "sim");
  const fs::path bag = WriteRos2BagOf(sim, "sqlite3");
  const fs::path out = kRoot / "imported";
  const RunResult r = RunMonomap("import rosbag " + bag.string() + " -o " +
                                 out.string() + kTopics);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("25 of 25 images imported (bgr8), 0 dropped"),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("mount from /tf_static base_footprint -> "
                          "camera_optical"),
            std::string::npos)
      << r.output;
  test::ExpectSameDataset(sim, LoadDataset(out));
}

TEST(ImportRos2E2e, BadBagsFailWithTheFileNamedAndNothingWritten) {
  const Dataset sim = test::SimulateHallway(kRoot / "sim");
  const fs::path bag = WriteRos2BagOf(sim, "sqlite3");
  RunResult r = RunMonomap("import rosbag " + bag.string() + " -o " +
                           (kRoot / "no_topic").string() +
                           " --image-topic /cam/image --camera-info-topic "
                           "/camera/camera_info --odom-topic /odom");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("no topic '/cam/image' in the bag; it has: "
                          "/camera/camera_info (sensor_msgs/msg/CameraInfo), "
                          "/camera/image_raw (sensor_msgs/msg/Image)"),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(kRoot / "no_topic"));

  const fs::path mcap = WriteRos2BagOf(sim, "mcap");
  r = RunMonomap("import rosbag " + mcap.string() + " -o " +
                 (kRoot / "mcap_out").string() + kTopics);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("hallway_mcap/metadata.yaml: field "
                          "'storage_identifier': 'mcap' is not supported"),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(kRoot / "mcap_out"));
}

}  // namespace
}  // namespace monomap
