#include "monomap/sim/robot.h"

#include <gtest/gtest.h>

#include <cmath>

#include "monomap/util/angles.h"
#include "monomap/util/error.h"

namespace monomap {
namespace {

double Drift(const std::vector<TimedPose2d>& a,
             const std::vector<TimedPose2d>& b) {
  return std::hypot(a.back().pose.x - b.back().pose.x,
                    a.back().pose.y - b.back().pose.y);
}

TEST(RobotTest, PathIsSmoothAtConstantSpeed) {
  for (const std::string& name : WorldNames()) {
    SCOPED_TRACE(name);
    const World w = MakeWorld(name, 1, 20.0);
    const RobotPath path(w);
    RobotPathOptions o;
    const auto poses = SampleRobotPath(path, o);
    EXPECT_GT(path.Length(), 5.0);
    ASSERT_GT(poses.size(), 300u);
    EXPECT_NEAR(poses[0].pose.x, w.path_keypoints[0].x(), 1e-9);
    EXPECT_NEAR(poses[0].pose.y, w.path_keypoints[0].y(), 1e-9);
    const double step = o.speed_mps / o.rate_hz;
    double max_dyaw = 0, max_step_err = 0, max_ddyaw = 0, prev_dyaw = 0;
    for (size_t k = 1; k < poses.size(); ++k) {
      EXPECT_NEAR(poses[k].timestamp - poses[k - 1].timestamp, 1 / 30.0,
                  1e-9);
      const double d = std::hypot(poses[k].pose.x - poses[k - 1].pose.x,
                                  poses[k].pose.y - poses[k - 1].pose.y);
      max_step_err = std::max(max_step_err, std::abs(d - step) / step);
      const double dyaw =
          std::remainder(poses[k].pose.yaw - poses[k - 1].pose.yaw, 2 * M_PI);
      max_dyaw = std::max(max_dyaw, std::abs(dyaw));
      if (k > 1) max_ddyaw = std::max(max_ddyaw, std::abs(dyaw - prev_dyaw));
      prev_dyaw = dyaw;
      // The heading is the direction of motion.
      EXPECT_LT(std::abs(std::remainder(
                    std::atan2(poses[k].pose.y - poses[k - 1].pose.y,
                               poses[k].pose.x - poses[k - 1].pose.x) -
                        poses[k].pose.yaw,
                    2 * M_PI)),
                0.05);
    }
    EXPECT_LT(max_step_err, 0.02);
    EXPECT_LT(max_dyaw, 0.05);     // < 1.5 rad/s
    EXPECT_LT(max_ddyaw, 0.01);    // no heading jumps
  }
}

TEST(RobotTest, MountLooksForwardAndSlightlyDown) {
  CameraMountOptions o;
  const Rigid3d base_from_cam = MakeCameraMount(o);
  const Eigen::Matrix3d r = base_from_cam.RotationMatrix();
  EXPECT_NEAR(r.determinant(), 1.0, 1e-12);
  const Eigen::Vector3d z = r.col(2), x = r.col(0);
  EXPECT_NEAR(z.z(), -std::sin(DegToRad(o.tilt_down_deg)), 1e-12);
  EXPECT_GT(z.x(), 0.98);
  EXPECT_NEAR(x.y(), -1.0, 1e-12);  // camera x = base right
  EXPECT_NEAR(base_from_cam.translation.z(), o.height_m, 1e-12);
  o.height_m = 0.0;
  EXPECT_THROW(MakeCameraMount(o), OptionsError);
}

TEST(RobotTest, NoiselessOdometryIsExact) {
  const World w = MakeWorld("room", 1, 20.0);
  const auto truth = SampleRobotPath(RobotPath(w), {});
  const auto odom = SimulateOdometry(truth, OdometryNoiseOptions::None(), 3);
  ASSERT_EQ(odom.size(), truth.size());
  for (size_t k = 0; k < truth.size(); ++k) {
    EXPECT_NEAR(odom[k].pose.x, truth[k].pose.x, 1e-9);
    EXPECT_NEAR(odom[k].pose.y, truth[k].pose.y, 1e-9);
    EXPECT_NEAR(std::remainder(odom[k].pose.yaw - truth[k].pose.yaw, 2 * M_PI),
                0.0, 1e-9);
  }
}

TEST(RobotTest, WheelRadiusErrorScalesDisplacement) {
  const World w = MakeWorld("hallway", 1, 20.0);
  const auto truth = SampleRobotPath(RobotPath(w), {});
  OdometryNoiseOptions o = OdometryNoiseOptions::None();
  o.wheel_radius_error = 0.01;
  const auto odom = SimulateOdometry(truth, o, 3);
  // With exact headings every step is 1% longer: the end point moves 1%
  // of the start-to-end displacement.
  const double disp = std::hypot(truth.back().pose.x - truth[0].pose.x,
                                 truth.back().pose.y - truth[0].pose.y);
  EXPECT_NEAR(Drift(truth, odom), 0.01 * disp, 1e-6);
}

TEST(RobotTest, DefaultDriftIsOneToFewPercent) {
  for (const std::string& name : WorldNames()) {
    const World w = MakeWorld(name, 1, 20.0);
    const auto truth = SampleRobotPath(RobotPath(w), {});
    const double length = PathLength(truth);
    double sum = 0;
    for (uint64_t seed = 1; seed <= 8; ++seed) {
      const auto odom = SimulateOdometry(truth, {}, seed);
      const double pct = 100.0 * Drift(truth, odom) / length;
      SCOPED_TRACE(name + " seed " + std::to_string(seed));
      EXPECT_GT(pct, 0.15);
      EXPECT_LT(pct, 4.0);
      sum += pct;
    }
    // Mean over seeds in the typical wheel-odometry band.
    EXPECT_GT(sum / 8, 0.5);
    EXPECT_LT(sum / 8, 3.0);
  }
  // Same seed, same odometry; different seed, different odometry.
  const World w = MakeWorld("hallway", 1, 20.0);
  const auto truth = SampleRobotPath(RobotPath(w), {});
  const auto a = SimulateOdometry(truth, {}, 4);
  const auto b = SimulateOdometry(truth, {}, 4);
  const auto c = SimulateOdometry(truth, {}, 5);
  EXPECT_EQ(a.back().pose.x, b.back().pose.x);
  EXPECT_NE(a.back().pose.x, c.back().pose.x);
}

// Signed distance of q to the left of the path (nearest point of a dense
// sampling of the whole path).
double LeftDistance(const RobotPath& path, const Pose2d& q) {
  double best = 1e300, signed_distance = 0.0;
  const int n = static_cast<int>(path.Length() / 5e-4);
  for (int i = 0; i <= n; ++i) {
    const Pose2d p = path.PoseAt(path.Length() * i / n);
    const double dx = q.x - p.x, dy = q.y - p.y;
    const double dist = std::hypot(dx, dy);
    if (dist < best) {
      best = dist;
      signed_distance = -std::sin(p.yaw) * dx + std::cos(p.yaw) * dy;
    }
  }
  return signed_distance;
}

TEST(RobotTest, StartOffsetOnAStraightPath) {
  const RobotPath path({{0, 0}, {10, 0}}, false);
  RobotPathOptions o;
  o.start_offset_m = 2.5;
  const auto poses = SampleRobotPath(path, o);
  const double step = o.speed_mps / o.rate_hz;
  ASSERT_EQ(poses.size(), static_cast<size_t>(std::floor(7.5 / step)) + 1);
  EXPECT_NEAR(poses[0].timestamp, o.start_time, 1e-12);
  for (size_t k = 0; k < poses.size(); ++k) {
    EXPECT_NEAR(poses[k].pose.x, 2.5 + k * step, 1e-6);
    EXPECT_NEAR(poses[k].pose.y, 0.0, 1e-9);
    EXPECT_NEAR(poses[k].pose.yaw, 0.0, 1e-9);
  }
  o.start_offset_m = 10.0;  // not shorter than the open path
  EXPECT_THROW(SampleRobotPath(path, o), OptionsError);
}

// Any requested length: a loop is driven lap after lap; an open path too
// short is refused with the most it holds (it used to stop silently).
TEST(RobotTest, RequestedLengthIsMetOrRefused) {
  RobotPathOptions o;
  const double step = o.speed_mps / o.rate_hz;
  const RobotPath line({{0, 0}, {10, 0}}, false);
  const int most = static_cast<int>(std::floor(10.0 / step)) + 1;
  EXPECT_EQ(SampleRobotPath(line, o, most).size(), static_cast<size_t>(most));
  try {
    SampleRobotPath(line, o, most + 1);
    FAIL() << "expected OptionsError";
  } catch (const OptionsError& e) {
    EXPECT_NE(std::string(e.what()).find("at most " + std::to_string(most)),
              std::string::npos)
        << e.what();
  }
  const RobotPath square({{0, 0}, {2, 0}, {2, 2}, {0, 2}}, true);
  for (const double offset : {0.0, 0.2}) {
    SCOPED_TRACE(offset);
    o.lateral_offset_m = offset;
    const int lap = static_cast<int>(SampleRobotPath(square, o).size());
    const auto poses = SampleRobotPath(square, o, 3 * lap);
    ASSERT_EQ(poses.size(), static_cast<size_t>(3 * lap));
    // Constant speed all along, across the lap boundaries too.
    for (size_t k = 1; k < poses.size(); ++k) {
      const double d = std::hypot(poses[k].pose.x - poses[k - 1].pose.x,
                                  poses[k].pose.y - poses[k - 1].pose.y);
      EXPECT_NEAR(d, step, 0.05 * step) << k;
      EXPECT_GT(poses[k].timestamp, poses[k - 1].timestamp);
    }
  }
}

TEST(RobotTest, LateralOffsetOnAStraightPathIsToTheLeft) {
  const RobotPath path({{0, 0}, {0, 10}}, false);  // heading +y: left is -x
  RobotPathOptions o;
  o.lateral_offset_m = 0.3;
  const auto poses = SampleRobotPath(path, o, 50);
  ASSERT_EQ(poses.size(), 50u);
  const double step = o.speed_mps / o.rate_hz;
  for (size_t k = 0; k < poses.size(); ++k) {
    EXPECT_NEAR(poses[k].pose.x, -0.3, 1e-9);
    EXPECT_NEAR(poses[k].pose.y, k * step, 1e-6);
    EXPECT_NEAR(poses[k].pose.yaw, M_PI / 2, 1e-9);
  }
  o.lateral_offset_m = -0.3;
  EXPECT_NEAR(SampleRobotPath(path, o, 5)[4].pose.x, 0.3, 1e-9);
}

TEST(RobotTest, OffsetPathIsParallelAtConstantSpeed) {
  for (const std::string& name : WorldNames()) {
    SCOPED_TRACE(name);
    const World w = MakeWorld(name, 1, 20.0);
    const RobotPath path(w);
    RobotPathOptions o;
    o.start_offset_m = 1.2;
    o.lateral_offset_m = 0.15;
    const auto poses = SampleRobotPath(path, o);
    ASSERT_GT(poses.size(), 100u);
    // Starts beside the path point 1.2 m along it.
    const Pose2d s = path.PoseAt(1.2);
    EXPECT_NEAR(poses[0].pose.x, s.x - 0.15 * std::sin(s.yaw), 1e-9);
    EXPECT_NEAR(poses[0].pose.y, s.y + 0.15 * std::cos(s.yaw), 1e-9);
    EXPECT_NEAR(poses[0].pose.yaw, s.yaw, 1e-9);
    const double step = o.speed_mps / o.rate_hz;
    for (size_t k = 0; k < poses.size(); k += 7) {
      EXPECT_NEAR(LeftDistance(path, poses[k].pose), 0.15, 2e-3) << k;
    }
    for (size_t k = 1; k < poses.size(); ++k) {
      const double dx = poses[k].pose.x - poses[k - 1].pose.x;
      const double dy = poses[k].pose.y - poses[k - 1].pose.y;
      EXPECT_NEAR(std::hypot(dx, dy), step, 0.02 * step) << k;
      // Still heading along the direction of motion.
      EXPECT_LT(std::abs(std::remainder(
                    std::atan2(dy, dx) - poses[k].pose.yaw, 2 * M_PI)),
                0.05);
    }
    if (path.closed()) {
      // A loop is still driven once around: it ends near its start.
      EXPECT_LT(std::hypot(poses.back().pose.x - poses[0].pose.x,
                           poses.back().pose.y - poses[0].pose.y),
                2 * step);
    } else {
      // An open path ends beside its end.
      const Pose2d e = path.PoseAt(path.Length());
      EXPECT_LT(
          std::hypot(poses.back().pose.x - (e.x - 0.15 * std::sin(e.yaw)),
                     poses.back().pose.y - (e.y + 0.15 * std::cos(e.yaw))),
          1.5 * step);
    }
  }
}

TEST(RobotTest, LateralOffsetBeyondATurnCentreThrows) {
  // A circle of radius ~1 m driven counter-clockwise: its centre is on the
  // left.
  std::vector<Eigen::Vector2d> circle;
  for (int i = 0; i < 12; ++i) {
    circle.emplace_back(std::cos(i * M_PI / 6), std::sin(i * M_PI / 6));
  }
  const RobotPath path(circle, true);
  RobotPathOptions o;
  o.lateral_offset_m = 0.5;  // inside: radius 0.5
  const auto inside = SampleRobotPath(path, o);
  EXPECT_NEAR(PathLength(inside), M_PI, 0.05);
  o.lateral_offset_m = -0.5;  // outside: radius 1.5
  EXPECT_NEAR(PathLength(SampleRobotPath(path, o)), 3 * M_PI, 0.05);
  o.lateral_offset_m = 1.2;  // beyond the centre
  EXPECT_THROW(SampleRobotPath(path, o), OptionsError);
  // A loop wraps around its first keypoint.
  o.lateral_offset_m = 0.0;
  o.start_offset_m = path.Length() + 0.5;
  const auto wrapped = SampleRobotPath(path, o);
  const Pose2d s = path.PoseAt(0.5);
  EXPECT_NEAR(wrapped[0].pose.x, s.x, 1e-9);
  EXPECT_NEAR(wrapped[0].pose.y, s.y, 1e-9);
  EXPECT_NEAR(PathLength(wrapped), path.Length(), 0.02);
}

TEST(RobotTest, OptionsAreChecked) {
  OdometryNoiseOptions o;
  o.translation_noise = -1;
  EXPECT_THROW(o.Check(), OptionsError);
  RobotPathOptions p;
  p.speed_mps = 0;
  EXPECT_THROW(p.Check(), OptionsError);
  p = RobotPathOptions();
  p.start_offset_m = -0.1;
  EXPECT_THROW(p.Check(), OptionsError);
  p = RobotPathOptions();
  p.lateral_offset_m = std::nan("");
  EXPECT_THROW(p.Check(), OptionsError);
  EXPECT_THROW(RobotPath({{0, 0}}, false), OptionsError);
}

}  // namespace
}  // namespace monomap
