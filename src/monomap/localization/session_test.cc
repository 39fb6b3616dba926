#include "monomap/localization/session.h"

#include <cmath>
#include <condition_variable>
#include <mutex>

#include <gtest/gtest.h>

#include "monomap/sim/test_scene.h"
#include "monomap/util/error.h"

namespace monomap {
namespace {

constexpr double kDeg = M_PI / 180.0;

Pose2d Compose(const Pose2d& a, double fwd, double turn) {
  return {a.x + fwd * std::cos(a.yaw), a.y + fwd * std::sin(a.yaw),
          WrapAngle(a.yaw + turn)};
}

// A drive through the test room: frames a robot would give the session
// (odometry with 5 % scale error, in its own origin) and the truth.
struct Drive {
  std::vector<SessionFrame> frames;
  std::vector<Rigid3d> truth;  // world_from_cam
};

Drive MakeDrive(const Renderer& renderer, const Camera& camera,
                const Rigid3d& mount, int steps) {
  Drive d;
  Pose2d truth{0.0, 0.0, 0.1}, odometry{0, 0, 0};
  for (int i = 0; i < steps; ++i) {
    if (i > 0) {
      truth = Compose(truth, 0.03, 1.0 * kDeg);
      odometry = Compose(odometry, 0.03 * 1.05, 1.1 * kDeg);
    }
    d.truth.push_back(WorldFromCamOfBase(truth, mount));
    SessionFrame f;
    f.stamp = 0.1 * i;
    f.image = testing::LiveImage(renderer, camera, d.truth.back(), 0.9, 10,
                                    2.0, 100 + i);
    f.odom_base = odometry;
    f.odom_from_cam = WorldFromCamOfBase(odometry, mount);
    d.frames.push_back(f);
  }
  return d;
}

class SessionTest : public ::testing::Test {
 public:
  SessionTest()
      : map_(std::make_shared<Map>(testing::RoomMap())),
        camera_(testing::LiveCamera()),
        mount_(testing::BaseFromCam()),
        renderer_(*map_),
        drive_(MakeDrive(renderer_, camera_, mount_, 25)) {}

  SessionOptions Options() const {
    SessionOptions o;
    o.localizer.method = LocalizationMethod::kMcc;
    o.localizer.state = LocalizationState::kPlanar;
    o.localizer.mcl.num_particles = 300;
    o.localizer.mcl.kld.max_particles = 300;
    o.localizer.init.pose = drive_.truth[0];
    o.localizer.seed = 5;
    return o;
  }

  double Error(const SessionResult& r, size_t frame) const {
    return (r.world_from_cam.translation - drive_.truth[frame].translation)
        .norm();
  }

  std::shared_ptr<const Map> map_;
  Camera camera_;
  Rigid3d mount_;
  Renderer renderer_;
  Drive drive_;
};

TEST_F(SessionTest, ProcessTracksWithCovarianceAndParticles) {
  LocalizationSession session(map_, camera_, Options(), mount_);
  double max_error = 0.0;
  SessionResult r;
  for (size_t i = 0; i < drive_.frames.size(); ++i) {
    r = session.Process(drive_.frames[i]);
    max_error = std::max(max_error, Error(r, i));
    EXPECT_EQ(r.status, SessionStatus::kTracking) << "frame " << i;
  }
  EXPECT_LT(max_error, 0.02);
  ASSERT_TRUE(r.world_from_base.has_value());
  // The base pose is the camera pose through the mount.
  EXPECT_LT(((*r.world_from_base * mount_).translation -
             r.world_from_cam.translation)
                .norm(),
            1e-9);
  EXPECT_FALSE(r.particles.empty());
  // A planar state: the covariance is spread in x, y and yaw only, and is
  // a proper covariance (symmetric, non-negative diagonal).
  EXPECT_GE(r.covariance(0, 0), 0.0);
  EXPECT_GT(r.covariance(0, 0) + r.covariance(1, 1), 0.0);
  EXPECT_LT(std::sqrt(r.covariance(0, 0) + r.covariance(1, 1)), 0.05);
  EXPECT_LT(std::abs(r.covariance(2, 2)), 1e-12);
  EXPECT_LT((r.covariance - r.covariance.transpose()).norm(), 1e-12);
  EXPECT_EQ(session.counters().processed, 25);
  EXPECT_EQ(session.counters().dropped, 0);
}

TEST_F(SessionTest, ThreadedReplayWithoutDropsEqualsProcess) {
  LocalizationSession sync(map_, camera_, Options(), mount_);
  std::vector<Rigid3d> expected;
  for (const SessionFrame& f : drive_.frames) {
    expected.push_back(sync.Process(f).world_from_cam);
  }
  SessionOptions o = Options();
  o.drop_when_busy = false;
  LocalizationSession threaded(map_, camera_, o, mount_);
  std::mutex m;
  std::vector<Rigid3d> got;
  threaded.Start([&](const SessionResult& r) {
    std::lock_guard<std::mutex> lock(m);
    got.push_back(r.world_from_cam);
  });
  for (const SessionFrame& f : drive_.frames) {
    EXPECT_TRUE(threaded.Push(f).accepted);
  }
  threaded.Flush();
  threaded.Stop();
  ASSERT_EQ(got.size(), expected.size());
  for (size_t i = 0; i < got.size(); ++i) {
    EXPECT_EQ(got[i].translation, expected[i].translation) << "frame " << i;
    EXPECT_EQ(got[i].rotation.coeffs(), expected[i].rotation.coeffs());
  }
  EXPECT_EQ(threaded.counters().dropped, 0);
}

TEST_F(SessionTest, DropsTheOlderOfTwoWaitingFrames) {
  // The callback holds the worker until the test has pushed two more
  // frames, so the older one of each pair is always replaced: frames 0, 2,
  // 4, ... are processed and the odd ones dropped, whatever the timing.
  LocalizationSession session(map_, camera_, Options(), mount_);
  std::mutex m;
  std::condition_variable cv;
  int seen = 0, released = 0;
  std::vector<SessionResult> results;
  session.Start([&](const SessionResult& r) {
    std::unique_lock<std::mutex> lock(m);
    results.push_back(r);
    ++seen;
    cv.notify_all();
    cv.wait(lock, [&] { return released >= seen; });
  });
  auto wait_for = [&](int n) {
    std::unique_lock<std::mutex> lock(m);
    cv.wait(lock, [&] { return seen >= n; });
  };
  auto release = [&](int n) {
    std::lock_guard<std::mutex> lock(m);
    released = n;
    cv.notify_all();
  };
  EXPECT_TRUE(session.Push(drive_.frames[0]).accepted);
  wait_for(1);
  int rounds = 0;
  for (size_t i = 1; i + 1 < drive_.frames.size(); i += 2) {
    EXPECT_TRUE(session.Push(drive_.frames[i]).accepted);
    EXPECT_TRUE(session.Push(drive_.frames[i + 1]).accepted);
    release(++rounds);
    wait_for(rounds + 1);
  }
  release(1 << 30);
  session.Flush();
  session.Stop();
  const SessionCounters c = session.counters();
  EXPECT_EQ(c.received, 25);
  EXPECT_EQ(c.dropped, 12);
  EXPECT_EQ(c.processed, 13);
  EXPECT_EQ(results.back().frames_dropped, 12);

  // The same as a synchronous run over the even frames: the odometry
  // increments span the dropped ones.
  LocalizationSession sync(map_, camera_, Options(), mount_);
  ASSERT_EQ(results.size(), 13u);
  for (size_t k = 0; k < results.size(); ++k) {
    const SessionResult r = sync.Process(drive_.frames[2 * k]);
    EXPECT_EQ(results[k].stamp, r.stamp);
    EXPECT_EQ(results[k].world_from_cam.translation,
              r.world_from_cam.translation)
        << "frame " << 2 * k;
  }
  EXPECT_LT(Error(results.back(), 24), 0.02);
}

TEST_F(SessionTest, RejectsBadFramesWithAReason) {
  SessionOptions o = Options();
  LocalizationSession session(map_, camera_, o, mount_);
  session.Start(nullptr);
  EXPECT_TRUE(session.Push(drive_.frames[1]).accepted);
  SessionFrame back = drive_.frames[0];  // stamp goes backwards
  PushOutcome out = session.Push(back);
  EXPECT_FALSE(out.accepted);
  EXPECT_NE(out.reason.find("not after"), std::string::npos) << out.reason;
  SessionFrame small = drive_.frames[2];
  cv::resize(small.image, small.image, cv::Size(160, 120));
  out = session.Push(small);
  EXPECT_FALSE(out.accepted);
  EXPECT_NE(out.reason.find("160x120"), std::string::npos) << out.reason;
  SessionFrame no_odometry = drive_.frames[3];
  no_odometry.odom_base.reset();
  out = session.Push(no_odometry);
  EXPECT_FALSE(out.accepted);
  EXPECT_NE(out.reason.find("planar"), std::string::npos) << out.reason;
  SessionFrame nan = drive_.frames[4];
  nan.odom_from_cam.translation.x() = std::nan("");
  EXPECT_FALSE(session.Push(nan).accepted);
  session.Flush();
  session.Stop();
  EXPECT_EQ(session.counters().rejected, 4);
  EXPECT_EQ(session.counters().processed, 1);
  // Process throws a typed error for the same frames.
  LocalizationSession sync(map_, camera_, o, mount_);
  EXPECT_THROW(sync.Process(small), InputError);
  // Push before Start is refused, Process while started is an error.
  LocalizationSession idle(map_, camera_, o, mount_);
  EXPECT_FALSE(idle.Push(drive_.frames[0]).accepted);
  idle.Start(nullptr);
  EXPECT_THROW(idle.Process(drive_.frames[0]), StageError);
}

TEST_F(SessionTest, SetPoseMovesTheFilter) {
  // Started around a wrong pose (0.3 m off), the filter is told the true
  // one, as rviz's "2D Pose Estimate" would.
  SessionOptions o = Options();
  // Started around a wrong pose (1.5 m and 90 degrees off), the filter is
  // told the true one, as rviz's "2D Pose Estimate" would.
  o.localizer.init.pose =
      WorldFromCamOfBase(Pose2d{1.5, 0.5, 0.1 + 90 * kDeg}, mount_);
  LocalizationSession session(map_, camera_, o, mount_);
  const SessionResult first = session.Process(drive_.frames[0]);
  EXPECT_GT(Error(first, 0), 0.1);
  session.SetPose(drive_.truth[1], 0.02, 2.0);
  double last = 0.0;
  for (size_t i = 1; i < 10; ++i) {
    last = Error(session.Process(drive_.frames[i]), i);
  }
  EXPECT_LT(last, 0.02);
  EXPECT_THROW(session.SetPose(drive_.truth[0], -1.0), OptionsError);
}

TEST(PoseCovariance, MatchesTheSpreadOfKnownPoses) {
  // Four poses +-0.1 m in x and +-2 deg about z around the identity.
  std::vector<Rigid3d> poses;
  for (const double s : {-1.0, 1.0}) {
    poses.push_back(Rigid3d(Eigen::Quaterniond::Identity(),
                            Eigen::Vector3d(0.1 * s, 0, 0)));
    poses.push_back(Rigid3d(
        Eigen::Quaterniond(Eigen::AngleAxisd(2 * kDeg * s,
                                             Eigen::Vector3d::UnitZ())),
        Eigen::Vector3d::Zero()));
  }
  const Eigen::Matrix<double, 6, 6> c =
      PoseCovariance(poses, {1, 1, 1, 1}, Rigid3d::Identity());
  EXPECT_NEAR(c(0, 0), 0.005, 1e-12);
  EXPECT_NEAR(c(5, 5), 0.5 * std::pow(2 * kDeg, 2), 1e-12);
  EXPECT_NEAR(c(1, 1) + c(2, 2) + c(3, 3) + c(4, 4), 0.0, 1e-12);
}

}  // namespace
}  // namespace monomap
