// The node end to end, as on a robot: a map built by `monomap build` from
// one simulated hallway traversal, a bag of a second, separate traversal
// (another run seed, starting further along the hallway), a ROS master on
// the loopback address, the node and `rosbag play` started as processes,
// the node's poses and tf received here. Every frame is queued (none
// dropped for lack of time), and the test waits until the node has worked
// through its queue. Checks the share of frames localized and their error
// against ground truth, that map -> odom closes the tf tree on the
// published pose, that a bad map exits cleanly with one fatal message, and
// that nothing is left running.
#include <arpa/inet.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <ros/ros.h>
#include <signal.h>
#include <std_msgs/String.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <tf2_msgs/TFMessage.h>
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
#include "monomap/util/angles.h"
#include "monomap/util/stats.h"
#include "ros/conversions.h"

namespace monomap {
namespace {
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

const fs::path kRoot =
    fs::temp_directory_path() / ("monomap_ros_e2e_" + std::to_string(getpid()));
// Bag stamps are the simulated ones plus this (ROS time 0 means "latest").
constexpr double kStampOffset = 1000.0;
constexpr double kTransformTolerance = 0.1;

bool HaveRosTools() {
  return std::system(
             "command -v rosmaster >/dev/null && "
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
  for (const std::string& a : args)
    argv.push_back(const_cast<char*>(a.c_str()));
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
      c->exit_code =
          WIFSIGNALED(status) ? 128 + WTERMSIG(status) : WEXITSTATUS(status);
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
  const std::string cmd = "pgrep -g " + std::to_string(c.pid) + " | wc -l";
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
  std::vector<std::pair<double, Rigid3d>> poses;          // stamp, map<-base
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

// The map's traversal and the bag's: 0.4 m/s at 30 Hz, so the map covers
// the first 1.2 m of the hallway and the live run 0.4 m to 1.0 m of it.
constexpr int kMapFrames = 90;
constexpr int kLiveFrames = 45;
constexpr double kLiveStartOffsetM = 0.4;

SimulationOptions Traversal(uint64_t run_seed, int frames,
                            double start_offset_m) {
  SimulationOptions so;
  so.world = "hallway";
  so.run_seed = run_seed;
  so.num_frames = frames;
  so.width = 320;
  so.height = 240;
  so.path.start_offset_m = start_offset_m;
  so.write_structure = false;  // the node gets the built map, not the truth
  return so;
}

// The map as a user makes it: a traversal, then `monomap build`.
void BuildMap(const fs::path& map_dir) {
  Simulate(Traversal(/*run_seed=*/1, kMapFrames, 0.0), kRoot / "map_run");
  Child build = Spawn({MONOMAP_BIN, "build", "-q", (kRoot / "map_run").string(),
                       "-o", map_dir.string()},
                      kRoot / "build.log");
  ASSERT_TRUE(WaitFor(&build, 300.0)) << "monomap build did not finish";
  ASSERT_EQ(build.exit_code, 0) << ReadAll(kRoot / "build.log");
}

// The node's status line: "<state> processed=N dropped=N rejected=N
// skipped_no_odometry=N".
struct Status {
  std::string state;
  int processed = 0, dropped = 0, rejected = 0, skipped = 0;
  int Seen() const { return processed + dropped + rejected + skipped; }
};

bool ParseStatus(const std::string& line, Status* s) {
  char state[64] = {};
  if (std::sscanf(line.c_str(),
                  "%63s processed=%d dropped=%d rejected=%d "
                  "skipped_no_odometry=%d",
                  state, &s->processed, &s->dropped, &s->rejected,
                  &s->skipped) != 5) {
    return false;
  }
  s->state = state;
  return true;
}

// Receives the node's poses, map -> odom on /tf and status.
class Listener {
 public:
  explicit Listener(Received* got) : spinner_(1) {
    pose_sub_ = nh_.subscribe<geometry_msgs::PoseWithCovarianceStamped>(
        "/amcl_pose", 100, [got](const auto& m) {
          std::lock_guard<std::mutex> lock(got->mutex);
          got->poses.emplace_back(m->header.stamp.toSec(),
                                  ros_adapter::RigidFromMsg(m->pose.pose));
        });
    tf_sub_ =
        nh_.subscribe<tf2_msgs::TFMessage>("/tf", 500, [got](const auto& m) {
          std::lock_guard<std::mutex> lock(got->mutex);
          for (const auto& t : m->transforms) {
            if (t.header.frame_id == "map" && t.child_frame_id == "odom") {
              got->map_from_odom.emplace_back(
                  t.header.stamp.toSec(),
                  ros_adapter::RigidFromMsg(t.transform));
            }
          }
        });
    status_sub_ = nh_.subscribe<std_msgs::String>(
        "/monomap_localization/status", 100, [got](const auto& m) {
          std::lock_guard<std::mutex> lock(got->mutex);
          got->status = m->data;
        });
    spinner_.start();
  }
  ~Listener() { spinner_.stop(); }

 private:
  ros::NodeHandle nh_;
  ros::Subscriber pose_sub_, tf_sub_, status_sub_;
  ros::AsyncSpinner spinner_;
};

std::string LatestStatus(Received* got) {
  std::lock_guard<std::mutex> lock(got->mutex);
  return got->status;
}

// Waits up to `seconds` for `done` to hold.
template <typename Pred>
bool WaitUntil(Pred done, double seconds) {
  const auto until = Clock::now() + std::chrono::duration<double>(seconds);
  while (!done() && Clock::now() < until) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return done();
}

// Until the node has accounted for every image of the bag, or its counts
// have not moved for 5 s (images the transport lost never arrive).
void WaitForTheQueueToDrain(Received* got, int images) {
  const auto until = Clock::now() + std::chrono::seconds(120);
  auto last_change = Clock::now();
  std::string last = LatestStatus(got);
  Status s;
  while (Clock::now() < until) {
    const std::string now = LatestStatus(got);
    if (ParseStatus(now, &s) && s.Seen() >= images) return;
    if (now != last) last_change = Clock::now();
    if (Clock::now() - last_change > std::chrono::seconds(5)) return;
    last = now;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

void InitRosClient() {
  char arg0[] = "monomap_e2e_listener";
  char* argv[] = {arg0, nullptr};
  int argc = 1;
  ros::init(
      argc, argv, "monomap_e2e_listener",
      ros::init_options::NoSigintHandler | ros::init_options::AnonymousName);
}

Child StartNode(const std::string& name, const fs::path& map_dir,
                const fs::path& log) {
  // Up to 100 frames wait for the filter: the bag's every frame is
  // localized whatever the machine's load (real-time figures with one
  // pending frame: bench/realtime_replay).
  std::vector<std::string> args = {
      MONOMAP_ROS_NODE,
      "__name:=" + name,
      "image:=/camera/image_raw",
      "camera_info:=/camera/camera_info",
      "_map_dir:=" + map_dir.string(),
      "_method:=mcc",
      "_particles:=200",
      "_transform_tolerance:=" + std::to_string(kTransformTolerance),
      "_drop_when_busy:=true",
      "_max_pending_frames:=100",
      "_camera_frame_id:=camera_optical"};
  return Spawn(args, log);
}

// The initial pose the node is given (~init_pose, as `monomap localize
// --init-pose`): the first frame's true base pose moved by kInitError, so
// that odometry alone stays that far off and only the images correct it.
const Rigid3d kInitError(YawRotation(DegToRad(4.0)),
                         Eigen::Vector3d(0.12, -0.08, 0.0));

// Sets the node's ~init_pose (the command line cannot give a list) and a
// spread covering kInitError, as a user's rough estimate.
void SetInitialPose(const std::string& node_name, const Dataset& live) {
  const Rigid3d world_from_base =
      *live.frames.front().groundtruth_world_from_cam *
      live.base_from_cam->Inverse() * kInitError;
  const Rigid3d world_from_cam = world_from_base * *live.base_from_cam;
  const Eigen::Vector3d& t = world_from_cam.translation;
  const Eigen::Quaterniond& q = world_from_cam.rotation;
  const std::string ns = "/" + node_name + "/";
  ros::param::set(
      ns + "init_pose",
      std::vector<double>{t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w()});
  ros::param::set(ns + "init_spread_m", 0.2);
  ros::param::set(ns + "init_spread_deg", 6.0);
}

// Starts the node on `map_dir`, publishes the mount, plays the bag at the
// camera's rate, and stops the node once it has drained its queue.
void RunNode(const fs::path& map_dir, const fs::path& bag, const Dataset& live,
             Received* got) {
  const int images = int(live.frames.size());
  Listener listener(got);
  SetInitialPose("monomap_localization", live);
  Child node = StartNode("monomap_localization", map_dir, kRoot / "node.log");
  // The node is up when its latched status arrives.
  ASSERT_TRUE(WaitUntil([&] { return !LatestStatus(got).empty(); }, 30.0))
      << ReadAll(kRoot / "node.log");
  // The mount first, latched and held for the whole run as
  // robot_state_publisher does: the node starts its session on it (given
  // ~camera_frame_id) before the images come. A one-shot `rosbag play` of
  // /tf_static could exit before the node's subscription connected.
  ros::NodeHandle nh;
  ros::Publisher mount =
      nh.advertise<tf2_msgs::TFMessage>("/tf_static", 1, /*latch=*/true);
  const double t0 = live.frames.front().timestamp + kStampOffset;
  mount.publish(rosbag_test::TfMsg(*live.base_from_cam, "base_link",
                                   "camera_optical", t0));
  ASSERT_TRUE(
      WaitUntil([&] { return LatestStatus(got).rfind("ready", 0) == 0; }, 60.0))
      << ReadAll(kRoot / "node.log");
  Child play = Spawn(
      {"rosbag", "play", "--quiet", "--wait-for-subscribers", bag.string()},
      kRoot / "play.log");
  EXPECT_TRUE(WaitFor(&play, 60.0)) << ReadAll(kRoot / "play.log");
  EXPECT_EQ(play.exit_code, 0) << ReadAll(kRoot / "play.log");
  WaitForTheQueueToDrain(got, images);
  std::this_thread::sleep_for(std::chrono::milliseconds(500));  // last tf
  EXPECT_TRUE(Stop(&node)) << "the node did not stop on SIGINT";
  EXPECT_EQ(node.exit_code, 0) << ReadAll(kRoot / "node.log");
  EXPECT_EQ(LeftRunning(node), 0);
  Stop(&play);
  EXPECT_EQ(LeftRunning(play), 0);
}

// Stamp (ms) -> frame index of the bag.
std::map<long, size_t> FrameOfStamp(const Dataset& live) {
  std::map<long, size_t> frame_of;
  for (size_t i = 0; i < live.frames.size(); ++i) {
    frame_of[std::lround((live.frames[i].timestamp + kStampOffset) * 1e3)] = i;
  }
  return frame_of;
}

// A pose counts as localized within this of the truth (m).
constexpr double kLocalizedM = 0.05;

struct PoseErrors {
  int n = 0;          // poses received
  int localized = 0;  // of them, within kLocalizedM
  double median_m = 0, worst_m = 0, median_deg = 0, worst_deg = 0;
};

// The published base poses against the true ones (the map is built in the
// simulated world's frame: `monomap build` anchors it on the odometry,
// which starts at the true pose).
PoseErrors ErrorsAgainstTruth(const Dataset& live, const Received& got) {
  const std::map<long, size_t> frame_of = FrameOfStamp(live);
  const Rigid3d cam_from_base = live.base_from_cam->Inverse();
  std::vector<double> meters, degrees;
  for (const auto& [stamp, world_from_base] : got.poses) {
    const auto f = frame_of.find(std::lround(stamp * 1e3));
    EXPECT_NE(f, frame_of.end()) << "pose at an unknown stamp " << stamp;
    if (f == frame_of.end()) continue;
    const Rigid3d truth =
        *live.frames[f->second].groundtruth_world_from_cam * cam_from_base;
    meters.push_back(
        (world_from_base.translation - truth.translation).head<2>().norm());
    degrees.push_back(
        RadToDeg(AngleBetween(world_from_base.rotation, truth.rotation)));
  }
  PoseErrors e;
  e.n = int(meters.size());
  if (e.n == 0) return e;
  e.median_m = Median(meters);
  e.median_deg = Median(degrees);
  e.worst_m = *std::max_element(meters.begin(), meters.end());
  e.worst_deg = *std::max_element(degrees.begin(), degrees.end());
  e.localized = int(std::count_if(meters.begin(), meters.end(),
                                  [](double m) { return m < kLocalizedM; }));
  return e;
}

// map -> odom (future-dated by the tolerance) after odom -> base at the
// image's stamp must give the published base pose. Returns the number of
// poses checked.
int CheckTfTree(const Dataset& live, const Received& got) {
  const std::map<long, size_t> frame_of = FrameOfStamp(live);
  std::map<long, Rigid3d> pose_at;
  for (const auto& [stamp, world_from_base] : got.poses) {
    pose_at[std::lround(stamp * 1e3)] = world_from_base;
  }
  int matched = 0;
  double worst_m = 0, worst_deg = 0;
  for (const auto& [stamp, world_from_odom] : got.map_from_odom) {
    const long key = std::lround((stamp - kTransformTolerance) * 1e3);
    const auto p = pose_at.find(key);
    if (p == pose_at.end() || !frame_of.count(key)) continue;
    const Rigid3d composed =
        world_from_odom * OdomFromBase(live.frames[frame_of.at(key)]);
    worst_m = std::max(worst_m,
                       (composed.translation - p->second.translation).norm());
    worst_deg =
        std::max(worst_deg,
                 RadToDeg(AngleBetween(composed.rotation, p->second.rotation)));
    ++matched;
  }
  EXPECT_LT(worst_m, 1e-3);
  EXPECT_LT(worst_deg, 0.1);
  return matched;
}

TEST_F(RosNodeE2e, LocalizesASecondTraversalOnABuiltMap) {
  const auto start = Clock::now();
  BuildMap(kRoot / "map");
  ASSERT_FALSE(HasFatalFailure());
  Simulate(Traversal(/*run_seed=*/2, kLiveFrames, kLiveStartOffsetM),
           kRoot / "live");
  const Dataset live = LoadDataset(kRoot / "live");
  ASSERT_TRUE(live.base_from_cam.has_value());
  ASSERT_EQ(int(live.frames.size()), kLiveFrames);
  WriteBag(live, kRoot / "live.bag");

  InitRosClient();
  Received got;
  RunNode(kRoot / "map", kRoot / "live.bag", live, &got);
  ASSERT_FALSE(HasFatalFailure());

  std::lock_guard<std::mutex> lock(got.mutex);
  const std::string log = ReadAll(kRoot / "node.log");
  Status s;
  ASSERT_TRUE(ParseStatus(got.status, &s)) << got.status;
  const PoseErrors e = ErrorsAgainstTruth(live, got);
  // Every frame gives a pose: none is dropped (the queue holds them all)
  // or rejected. On a loaded machine the transport may lose an image, or
  // deliver one before the odometry at its stamp while another waits for
  // it (the node then skips the older one): at most two such.
  EXPECT_EQ(s.processed, e.n);
  EXPECT_EQ(s.dropped, 0);
  EXPECT_EQ(s.rejected, 0);
  EXPECT_LE(s.skipped, 2) << log;
  EXPECT_GE(e.n, kLiveFrames - 2) << log;
  EXPECT_EQ(s.state, "tracking") << got.status;
  ASSERT_GT(e.n, 0) << log;
  // Odometry alone stays kInitError (144 mm) off: the images must pull the
  // estimate onto the truth within the first frames and keep it there.
  const double localized_share = double(e.localized) / kLiveFrames;
  EXPECT_GE(localized_share, 0.85);
  EXPECT_LT(e.median_m, 0.035);
  EXPECT_LT(e.median_deg, 1.0);
  const int matched = CheckTfTree(live, got);
  EXPECT_EQ(matched, e.n);
  const double seconds =
      std::chrono::duration<double>(Clock::now() - start).count();
  std::printf(
      "ros e2e: %d poses of %d frames, %d within %.0f mm (%.0f%%) on a built "
      "map; position median %.1f mm, worst %.1f mm; heading median %.2f deg, "
      "worst %.2f deg; tf: %d matched; status '%s'; %.1f s\n",
      e.n, kLiveFrames, e.localized, 1e3 * kLocalizedM, 100.0 * localized_share,
      1e3 * e.median_m, 1e3 * e.worst_m, e.median_deg, e.worst_deg, matched,
      got.status.c_str(), seconds);
}

// A map directory that does not load: one fatal message naming it, exit
// code 1, no crash.
TEST_F(RosNodeE2e, ABadMapExitsWithOneFatalMessage) {
  Child node =
      StartNode("monomap_bad_map", kRoot / "no_such_map", kRoot / "bad.log");
  ASSERT_TRUE(WaitFor(&node, 30.0)) << ReadAll(kRoot / "bad.log");
  const std::string log = ReadAll(kRoot / "bad.log");
  EXPECT_EQ(node.exit_code, 1) << log;
  EXPECT_NE(log.find("cannot load the map"), std::string::npos) << log;
  EXPECT_NE(log.find("no_such_map"), std::string::npos) << log;
  EXPECT_EQ(LeftRunning(node), 0);
}

}  // namespace
}  // namespace monomap
