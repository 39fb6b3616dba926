// The node end to end, as on a robot: a simulated hallway traversal written
// to a ROS 1 bag, a ROS master on the loopback address, the node and
// `rosbag play` started as processes, the node's poses and tf received
// here. Checks the poses against ground truth, that map -> odom closes the
// tf tree on the published pose, that a bad map exits cleanly with one
// fatal message, and that nothing is left running.
#include <arpa/inet.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <ros/ros.h>
#include <signal.h>
#include <std_msgs/String.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "monomap/io/dataset.h"
#include "monomap/io/rosbag_test_bag.h"
#include "monomap/sim/simulate.h"
#include "ros/conversions.h"

namespace monomap {
namespace {
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

const fs::path kRoot = fs::temp_directory_path() /
                       ("monomap_ros_e2e_" + std::to_string(getpid()));
// Bag stamps are the simulated ones plus this (ROS time 0 means "latest").
constexpr double kStampOffset = 1000.0;
constexpr double kTransformTolerance = 0.1;

bool HaveRosTools() {
  return std::system("command -v rosmaster >/dev/null && "
                     "command -v rosbag >/dev/null") == 0;
}

int FreePort() {
  const int s = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = 0;
  socklen_t len = sizeof(a);
  bind(s, reinterpret_cast<sockaddr*>(&a), sizeof(a));
  getsockname(s, reinterpret_cast<sockaddr*>(&a), &len);
  close(s);
  return ntohs(a.sin_port);
}

bool PortOpen(int port) {
  const int s = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = htons(port);
  const bool ok = connect(s, reinterpret_cast<sockaddr*>(&a), sizeof(a)) == 0;
  close(s);
  return ok;
}

// A child process in its own process group (so that everything it starts
// is stopped with it), output to `log`.
struct Child {
  pid_t pid = -1;
  int exit_code = -1;  // 128 + signal if killed
};

Child Spawn(const std::vector<std::string>& args, const fs::path& log) {
  Child c;
  c.pid = fork();
  if (c.pid != 0) return c;
  setpgid(0, 0);
  if (std::freopen(log.c_str(), "w", stdout) == nullptr) _exit(120);
  dup2(fileno(stdout), fileno(stderr));
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  execvp(argv[0], argv.data());
  _exit(121);
}

// Waits up to `seconds` for the child to end; true if it did.
bool WaitFor(Child* c, double seconds) {
  const auto until = Clock::now() + std::chrono::duration<double>(seconds);
  while (Clock::now() < until) {
    int status = 0;
    const pid_t r = waitpid(c->pid, &status, WNOHANG);
    if (r == c->pid) {
      c->exit_code = WIFSIGNALED(status) ? 128 + WTERMSIG(status)
                                         : WEXITSTATUS(status);
      return true;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

// SIGINT to the group (as Ctrl-C), SIGKILL after `seconds`. True if it
// ended on SIGINT.
bool Stop(Child* c, double seconds = 10.0) {
  if (c->pid <= 0) return true;
  if (c->exit_code >= 0) return true;
  kill(-c->pid, SIGINT);
  if (WaitFor(c, seconds)) return true;
  kill(-c->pid, SIGKILL);
  WaitFor(c, 5.0);
  return false;
}

// Processes left in the group of `c` (pgrep -g).
int LeftRunning(const Child& c) {
  const std::string cmd =
      "pgrep -g " + std::to_string(c.pid) + " | wc -l";
  FILE* p = popen(cmd.c_str(), "r");
  int n = -1;
  if (p) {
    if (std::fscanf(p, "%d", &n) != 1) n = -1;
    pclose(p);
  }
  return n;
}

std::string ReadAll(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

Rigid3d OdomFromBase(const DatasetFrame& f) {
  const Pose2d& b = *f.odometry_base;
  return Rigid3d(YawRotation(b.yaw), Eigen::Vector3d(b.x, b.y, 0.0));
}

// The run as a robot logs it: camera_info and images, nav_msgs/Odometry
// and /tf odom -> base, /tf_static base -> camera.
void WriteBag(const Dataset& sim, const fs::path& path) {
  using namespace rosbag_test;
  rosbag::Bag bag(path.string(), rosbag::bagmode::Write);
  const double t0 = sim.frames.front().timestamp + kStampOffset;
  bag.write("/tf_static", ros::Time(t0),
            TfMsg(*sim.base_from_cam, "base_link", "camera_optical", t0));
  for (size_t i = 0; i < sim.frames.size(); ++i) {
    const DatasetFrame& f = sim.frames[i];
    const double t = f.timestamp + kStampOffset;
    bag.write("/odom", ros::Time(t),
              OdometryMsg(OdomFromBase(f), "odom", "base_link", t));
    bag.write("/tf", ros::Time(t),
              TfMsg(OdomFromBase(f), "odom", "base_link", t));
    bag.write("/camera/camera_info", ros::Time(t),
              CameraInfoMsg(sim.camera, "camera_optical", t));
    bag.write("/camera/image_raw", ros::Time(t),
              ImageMsg(sim.LoadImage(i, /*color=*/true), "bgr8",
                       "camera_optical", t));
  }
  bag.close();
}

// What the test receives from the node.
struct Received {
  std::mutex mutex;
  std::vector<std::pair<double, Rigid3d>> poses;         // stamp, map<-base
  std::vector<std::pair<double, Rigid3d>> map_from_odom;  // tf stamp, T
  std::string status;
};

class RosNodeE2e : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!HaveRosTools()) GTEST_SKIP() << "rosmaster / rosbag not installed";
    fs::remove_all(kRoot);
    port_ = FreePort();
    const std::string uri = "http://127.0.0.1:" + std::to_string(port_);
    setenv("ROS_MASTER_URI", uri.c_str(), 1);
    setenv("ROS_IP", "127.0.0.1", 1);
    setenv("ROS_HOME", (kRoot / "ros_home").c_str(), 1);
    fs::create_directories(kRoot / "ros_home");
    master_ = Spawn({"rosmaster", "--core", "-p", std::to_string(port_)},
                    kRoot / "master.log");
    const auto until = Clock::now() + std::chrono::seconds(30);
    while (!PortOpen(port_) && Clock::now() < until) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    ASSERT_TRUE(PortOpen(port_)) << ReadAll(kRoot / "master.log");
  }
  void TearDown() override {
    Stop(&master_);
    if (master_.pid > 0) {
      EXPECT_EQ(LeftRunning(master_), 0);
    }
    // MONOMAP_KEEP_TEST_DIR=1 keeps the bag and the logs to look at.
    if (!std::getenv("MONOMAP_KEEP_TEST_DIR")) fs::remove_all(kRoot);
  }
  int port_ = 0;
  Child master_;
};

Child StartNode(const std::string& name, const fs::path& map_dir,
                const fs::path& log) {
  return Spawn({MONOMAP_ROS_NODE, "__name:=" + name,
                "image:=/camera/image_raw",
                "camera_info:=/camera/camera_info", "_map_dir:=" +
                map_dir.string(), "_method:=mcc", "_particles:=200",
                "_transform_tolerance:=" + std::to_string(kTransformTolerance),
                "_drop_when_busy:=true", "_camera_frame_id:=camera_optical"},
               log);
}

TEST_F(RosNodeE2e, LocalizesABagAndClosesTheTfTree) {
  const auto start = Clock::now();
  SimulationOptions so;
  so.world = "hallway";
  so.num_frames = 80;
  so.width = 320;
  so.height = 240;
  Simulate(so, kRoot / "sim");  // also writes the true planes as a map
  const Dataset sim = LoadDataset(kRoot / "sim");
  ASSERT_TRUE(sim.base_from_cam.has_value());
  WriteBag(sim, kRoot / "run.bag");

  char arg0[] = "monomap_e2e_listener";
  char* argv[] = {arg0, nullptr};
  int argc = 1;
  ros::init(argc, argv, "monomap_e2e_listener",
            ros::init_options::NoSigintHandler |
                ros::init_options::AnonymousName);
  Received got;
  {
    ros::NodeHandle nh;
    const ros::Subscriber pose_sub =
        nh.subscribe<geometry_msgs::PoseWithCovarianceStamped>(
            "/amcl_pose", 100, [&](const auto& m) {
              std::lock_guard<std::mutex> lock(got.mutex);
              got.poses.emplace_back(m->header.stamp.toSec(),
                                     ros_adapter::RigidFromMsg(m->pose.pose));
            });
    const ros::Subscriber tf_sub = nh.subscribe<tf2_msgs::TFMessage>(
        "/tf", 500, [&](const auto& m) {
          std::lock_guard<std::mutex> lock(got.mutex);
          for (const auto& t : m->transforms) {
            if (t.header.frame_id == "map" && t.child_frame_id == "odom") {
              got.map_from_odom.emplace_back(
                  t.header.stamp.toSec(),
                  ros_adapter::RigidFromMsg(t.transform));
            }
          }
        });
    const ros::Subscriber status_sub = nh.subscribe<std_msgs::String>(
        "/monomap_localization/status", 100, [&](const auto& m) {
          std::lock_guard<std::mutex> lock(got.mutex);
          got.status = m->data;
        });
    ros::AsyncSpinner spinner(1);
    spinner.start();

    Child node = StartNode("monomap_localization", kRoot / "sim/structure",
                           kRoot / "node.log");
    // The node is up when its latched status arrives.
    auto until = Clock::now() + std::chrono::seconds(30);
    auto status = [&] {
      std::lock_guard<std::mutex> lock(got.mutex);
      return got.status;
    };
    while (status().empty() && Clock::now() < until) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    ASSERT_FALSE(status().empty()) << ReadAll(kRoot / "node.log");
    // The mount first, as robot_state_publisher would: the node starts
    // its session on it (given ~camera_frame_id) before the images come.
    Child mount = Spawn({"rosbag", "play", "--quiet", "--wait-for-subscribers",
                         "--topics", "/tf_static", "--",
                         (kRoot / "run.bag").string()},
                        kRoot / "mount.log");
    EXPECT_TRUE(WaitFor(&mount, 60.0)) << ReadAll(kRoot / "mount.log");
    until = Clock::now() + std::chrono::seconds(60);
    while (status().rfind("ready", 0) != 0 && Clock::now() < until) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    ASSERT_EQ(status().rfind("ready", 0), 0u) << ReadAll(kRoot / "node.log");
    // A quarter of the camera's rate (the test machine is shared), once the
    // node is connected to every topic.
    Child play = Spawn({"rosbag", "play", "--quiet", "--wait-for-subscribers", "-r", "0.25",
                        (kRoot / "run.bag").string()},
                       kRoot / "play.log");
    EXPECT_TRUE(WaitFor(&play, 60.0)) << ReadAll(kRoot / "play.log");
    EXPECT_EQ(play.exit_code, 0) << ReadAll(kRoot / "play.log");
    std::this_thread::sleep_for(std::chrono::seconds(2));  // last results
    EXPECT_TRUE(Stop(&node)) << "the node did not stop on SIGINT";
    EXPECT_EQ(node.exit_code, 0) << ReadAll(kRoot / "node.log");
    EXPECT_EQ(LeftRunning(node), 0);
    Stop(&play);
    EXPECT_EQ(LeftRunning(play), 0);
    spinner.stop();
  }

  const std::string log = ReadAll(kRoot / "node.log");
  std::lock_guard<std::mutex> lock(got.mutex);
  // Poses against ground truth (the base in the map, which is the
  // simulated world).
  std::map<long, size_t> frame_of;  // stamp in ms -> frame
  for (size_t i = 0; i < sim.frames.size(); ++i) {
    frame_of[std::lround((sim.frames[i].timestamp + kStampOffset) * 1e3)] = i;
  }
  const Rigid3d cam_from_base = sim.base_from_cam->Inverse();
  std::vector<double> errors;
  std::map<long, Rigid3d> pose_at;
  for (const auto& [stamp, world_from_base] : got.poses) {
    const auto f = frame_of.find(std::lround(stamp * 1e3));
    ASSERT_NE(f, frame_of.end()) << "pose at an unknown stamp " << stamp;
    const Rigid3d truth =
        *sim.frames[f->second].groundtruth_world_from_cam * cam_from_base;
    errors.push_back((world_from_base.translation - truth.translation)
                         .head<2>()
                         .norm());
    pose_at[f->first] = world_from_base;
  }
  const int n = int(errors.size());
  // Each processed frame gives a pose; frames dropped while busy do not.
  EXPECT_GE(n, 40) << log;
  ASSERT_GT(n, 0);
  std::nth_element(errors.begin(), errors.begin() + n / 2, errors.end());
  const double median = errors[n / 2];
  const double worst = *std::max_element(errors.begin(), errors.end());
  EXPECT_LT(median, 0.05);
  EXPECT_LT(worst, 0.25);

  // map -> odom (future-dated by the tolerance) after odom -> base at the
  // image's stamp gives the published base pose.
  int matched = 0;
  double worst_m = 0, worst_deg = 0;
  for (const auto& [stamp, world_from_odom] : got.map_from_odom) {
    const long key = std::lround((stamp - kTransformTolerance) * 1e3);
    const auto p = pose_at.find(key);
    if (p == pose_at.end()) continue;
    const Rigid3d composed =
        world_from_odom * OdomFromBase(sim.frames[frame_of.at(key)]);
    worst_m = std::max(
        worst_m, (composed.translation - p->second.translation).norm());
    worst_deg = std::max(worst_deg, AngleBetween(composed.rotation,
                                                 p->second.rotation) *
                                        180.0 / M_PI);
    ++matched;
  }
  EXPECT_EQ(matched, n);
  EXPECT_LT(worst_m, 1e-3);
  EXPECT_LT(worst_deg, 0.1);
  EXPECT_NE(got.status.find("tracking"), std::string::npos) << got.status;
  // Every image is accounted for: processed (one pose each), dropped by
  // the session while busy, or skipped without odometry; the transport
  // may lose a few on a loaded machine.
  int processed = -1, dropped = -1, rejected = -1, skipped = -1;
  ASSERT_EQ(std::sscanf(got.status.c_str(),
                        "%*s processed=%d dropped=%d rejected=%d "
                        "skipped_no_odometry=%d",
                        &processed, &dropped, &rejected, &skipped),
            4)
      << got.status;
  EXPECT_EQ(processed, n);
  EXPECT_EQ(rejected, 0);
  EXPECT_GE(processed + dropped + skipped, 72);
  const double seconds =
      std::chrono::duration<double>(Clock::now() - start).count();
  std::printf(
      "ros e2e: %d of %zu frames localized, median %.4f m, worst %.4f m; "
      "tf: %d matched, worst %.2e m / %.2e deg; status '%s'; %.1f s\n",
      n, sim.frames.size(), median, worst, matched, worst_m, worst_deg,
      got.status.c_str(), seconds);
}

// A map directory that does not load: one fatal message naming it, exit
// code 1, no crash.
TEST_F(RosNodeE2e, ABadMapExitsWithOneFatalMessage) {
  Child node = StartNode("monomap_bad_map", kRoot / "no_such_map",
                         kRoot / "bad.log");
  ASSERT_TRUE(WaitFor(&node, 30.0)) << ReadAll(kRoot / "bad.log");
  const std::string log = ReadAll(kRoot / "bad.log");
  EXPECT_EQ(node.exit_code, 1) << log;
  EXPECT_NE(log.find("cannot load the map"), std::string::npos) << log;
  EXPECT_NE(log.find("no_such_map"), std::string::npos) << log;
  EXPECT_EQ(LeftRunning(node), 0);
}

}  // namespace
}  // namespace monomap
