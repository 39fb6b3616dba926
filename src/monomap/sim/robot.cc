#include "monomap/sim/robot.h"

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>

#include "monomap/util/angles.h"
#include "monomap/util/error.h"

namespace monomap {
namespace {

using Eigen::Vector2d;

double WrapAngle(double a) { return std::remainder(a, 2.0 * M_PI); }

Eigen::Matrix2d Rot2(double yaw) {
  Eigen::Matrix2d r;
  r << std::cos(yaw), -std::sin(yaw), std::sin(yaw), std::cos(yaw);
  return r;
}

}  // namespace

void CameraMountOptions::Check() const {
  CheckOption(height_m > 0.05 && height_m < 3.0, "mount.height_m",
              "must be in (0.05, 3) m");
  CheckOption(std::isfinite(forward_m) && std::abs(forward_m) < 2.0,
              "mount.forward_m", "must be within 2 m");
  CheckOption(std::abs(tilt_down_deg) < 80.0, "mount.tilt_down_deg",
              "must be within +-80 degrees");
  CheckOption(std::abs(yaw_left_deg) <= 180.0, "mount.yaw_left_deg",
              "must be within +-180 degrees");
}

Rigid3d MakeCameraMount(const CameraMountOptions& options) {
  options.Check();
  // Columns: camera x (right), y (down), z (forward) in the base frame.
  Eigen::Matrix3d level;
  level.col(0) = -Eigen::Vector3d::UnitY();
  level.col(1) = -Eigen::Vector3d::UnitZ();
  level.col(2) = Eigen::Vector3d::UnitX();
  // Tilting down turns z towards +y of the camera: rotate about camera x.
  const Eigen::Matrix3d tilt =
      Eigen::AngleAxisd(DegToRadMulDiv(-options.tilt_down_deg),
                        Eigen::Vector3d::UnitX())
          .toRotationMatrix();
  const Eigen::Matrix3d yaw =
      Eigen::AngleAxisd(DegToRadMulDiv(options.yaw_left_deg),
                        Eigen::Vector3d::UnitZ())
          .toRotationMatrix();
  return Rigid3d(Eigen::Quaterniond(yaw * level * tilt),
                 Eigen::Vector3d(options.forward_m, 0.0, options.height_m));
}

void RobotPathOptions::Check() const {
  CheckOption(speed_mps > 0.0 && speed_mps < 5.0, "path.speed_mps",
              "must be in (0, 5) m/s");
  CheckOption(rate_hz >= 1.0 && rate_hz <= 1000.0, "path.rate_hz",
              "must be in [1, 1000] Hz");
  CheckOption(std::isfinite(start_time) && start_time >= 0.0, "path.start_time",
              "must be >= 0");
  CheckOption(std::isfinite(start_offset_m) && start_offset_m >= 0.0,
              "path.start_offset_m", "must be >= 0");
  CheckOption(
      std::isfinite(lateral_offset_m) && std::abs(lateral_offset_m) < 5.0,
      "path.lateral_offset_m", "must be within +-5 m");
}

RobotPath::RobotPath(std::vector<Vector2d> keypoints, bool closed)
    : closed_(closed) {
  const size_t n = keypoints.size();
  if (n < (closed ? 3u : 2u)) {
    throw OptionsError("path: needs at least " +
                       std::to_string(closed ? 3 : 2) + " keypoints");
  }
  if (closed) {
    ctrl_.push_back(keypoints[n - 1]);
    ctrl_.insert(ctrl_.end(), keypoints.begin(), keypoints.end());
    ctrl_.push_back(keypoints[0]);
    ctrl_.push_back(keypoints[1]);
    segments_ = static_cast<int>(n);
  } else {
    ctrl_.push_back(2.0 * keypoints[0] - keypoints[1]);
    ctrl_.insert(ctrl_.end(), keypoints.begin(), keypoints.end());
    ctrl_.push_back(2.0 * keypoints[n - 1] - keypoints[n - 2]);
    segments_ = static_cast<int>(n) - 1;
  }
  constexpr int kSteps = 400;
  Vector2d prev = Point(0.0, nullptr);
  table_u_.push_back(0.0);
  table_s_.push_back(0.0);
  for (int i = 1; i <= segments_ * kSteps; ++i) {
    const double u = static_cast<double>(i) / kSteps;
    const Vector2d p = Point(u, nullptr);
    table_u_.push_back(u);
    table_s_.push_back(table_s_.back() + (p - prev).norm());
    prev = p;
  }
}

Vector2d RobotPath::Point(double u, Vector2d* tangent) const {
  const int seg = std::clamp(static_cast<int>(std::floor(u)), 0, segments_ - 1);
  const double t = u - seg;
  const Vector2d& p0 = ctrl_[seg];
  const Vector2d& p1 = ctrl_[seg + 1];
  const Vector2d& p2 = ctrl_[seg + 2];
  const Vector2d& p3 = ctrl_[seg + 3];
  const Vector2d a = 2.0 * p1;
  const Vector2d b = p2 - p0;
  const Vector2d c = 2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3;
  const Vector2d d = -p0 + 3.0 * p1 - 3.0 * p2 + p3;
  if (tangent) *tangent = 0.5 * (b + 2.0 * c * t + 3.0 * d * t * t);
  return 0.5 * (a + b * t + c * t * t + d * t * t * t);
}

Pose2d RobotPath::PoseAt(double s) const {
  s = std::clamp(s, 0.0, Length());
  const auto it = std::lower_bound(table_s_.begin(), table_s_.end(), s);
  size_t i = std::clamp<size_t>(it - table_s_.begin(), 1, table_s_.size() - 1);
  const double ds = table_s_[i] - table_s_[i - 1];
  const double f = ds > 0 ? (s - table_s_[i - 1]) / ds : 0.0;
  const double u = table_u_[i - 1] + f * (table_u_[i] - table_u_[i - 1]);
  Vector2d tangent;
  const Vector2d p = Point(u, &tangent);
  return Pose2d{p.x(), p.y(), std::atan2(tangent.y(), tangent.x())};
}

namespace {

// Drives a path from a start offset, optionally at a lateral offset: the
// distance driven -> the pose. A closed path is driven lap after lap.
struct PathDriver {
  const RobotPath& path;
  double length;
  double start;
  double lateral_offset_m;

  Pose2d BasePose(double driven) const {
    double s = start + driven;
    if (path.closed()) s = std::fmod(s, length);
    return path.PoseAt(s);
  }
  Pose2d OffsetPose(double driven) const {
    Pose2d p = BasePose(driven);
    p.x -= lateral_offset_m * std::sin(p.yaw);
    p.y += lateral_offset_m * std::cos(p.yaw);
    return p;
  }
};

// The samples `driven_length` holds at `step`, or max_samples if positive.
// An open path ends: more samples than it holds are refused, not cut.
int SampleCount(bool closed, double step, double driven_length,
                int max_samples) {
  const int n = static_cast<int>(std::floor(driven_length / step)) + 1;
  if (max_samples <= 0) return n;
  if (max_samples > n && !closed) {
    throw OptionsError(
        "num_frames: " + std::to_string(max_samples) + " frames need " +
        std::to_string((max_samples - 1) * step) +
        " m of path, but the "
        "open path has " +
        std::to_string(driven_length) + " m (at most " + std::to_string(n) +
        " frames at this speed and rate); lower the "
        "speed or the number of frames");
  }
  return max_samples;
}

// The parallel curve shares the path's tangents; its arc length differs
// in turns (ds' = (1 - curvature * d) ds), so tabulate it (distance driven
// on the path -> on the offset curve) to drive it at constant speed.
void TabulateOffsetCurve(const PathDriver& driver, double span,
                         std::vector<double>* table_driven,
                         std::vector<double>* table_offset) {
  constexpr double kTableStep = 1e-3;  // m of the path
  const int m = std::max(1, static_cast<int>(std::ceil(span / kTableStep)));
  table_driven->assign(m + 1, 0.0);
  table_offset->assign(m + 1, 0.0);
  Pose2d prev = driver.OffsetPose(0.0);
  for (int i = 1; i <= m; ++i) {
    (*table_driven)[i] = span * i / m;
    const Pose2d p = driver.OffsetPose((*table_driven)[i]);
    const Vector2d delta(p.x - prev.x, p.y - prev.y);
    // Moving forward at less than a tenth of the path's speed: the offset
    // is (nearly) at the turn's centre.
    if (delta.dot(Vector2d(std::cos(p.yaw), std::sin(p.yaw))) <
        0.1 * ((*table_driven)[i] - (*table_driven)[i - 1])) {
      throw OptionsError(
          "path.lateral_offset_m: " + std::to_string(driver.lateral_offset_m) +
          " m reaches the centre of a turn of the path");
    }
    (*table_offset)[i] = (*table_offset)[i - 1] + delta.norm();
    prev = p;
  }
}

// The offset curve's pose after `target` m driven along it.
Pose2d OffsetPoseAt(const PathDriver& driver,
                    const std::vector<double>& table_driven,
                    const std::vector<double>& table_offset, double target) {
  const auto it =
      std::lower_bound(table_offset.begin(), table_offset.end(), target);
  const size_t i =
      std::clamp<size_t>(it - table_offset.begin(), 1, table_offset.size() - 1);
  const double ds = table_offset[i] - table_offset[i - 1];
  const double f = ds > 0 ? (target - table_offset[i - 1]) / ds : 0.0;
  return driver.OffsetPose(table_driven[i - 1] +
                           f * (table_driven[i] - table_driven[i - 1]));
}

}  // namespace

std::vector<TimedPose2d> SampleRobotPath(const RobotPath& path,
                                         const RobotPathOptions& options,
                                         int max_samples) {
  options.Check();
  const double length = path.Length();
  if (!path.closed() && !(options.start_offset_m < length)) {
    throw OptionsError(
        "path.start_offset_m: must be shorter than the open "
        "path (" +
        std::to_string(length) + " m)");
  }
  // Distance driven along the path from the start offset -> path pose.
  const double start = path.closed() ? std::fmod(options.start_offset_m, length)
                                     : options.start_offset_m;
  const double span = path.closed() ? length : length - start;
  const PathDriver driver{path, length, start, options.lateral_offset_m};
  const double step = options.speed_mps / options.rate_hz;

  if (options.lateral_offset_m == 0.0) {
    const int n = SampleCount(path.closed(), step, span, max_samples);
    std::vector<TimedPose2d> out(n);
    for (int k = 0; k < n; ++k) {
      out[k].timestamp = options.start_time + k / options.rate_hz;
      out[k].pose = driver.BasePose(k * step);
    }
    return out;
  }

  std::vector<double> table_driven, table_offset;
  TabulateOffsetCurve(driver, span, &table_driven, &table_offset);
  const double total = table_offset.back();
  const int n = SampleCount(path.closed(), step, total, max_samples);
  std::vector<TimedPose2d> out(n);
  for (int k = 0; k < n; ++k) {
    const double target =
        path.closed() ? std::fmod(k * step, total) : std::min(k * step, total);
    out[k].timestamp = options.start_time + k / options.rate_hz;
    out[k].pose = OffsetPoseAt(driver, table_driven, table_offset, target);
  }
  return out;
}

OdometryNoiseOptions OdometryNoiseOptions::None() {
  OdometryNoiseOptions o;
  o.wheel_radius_error = 0.0;
  o.yaw_scale_error = 0.0;
  o.translation_noise = 0.0;
  o.rotation_noise_per_meter = 0.0;
  o.rotation_noise_per_radian = 0.0;
  return o;
}

void OdometryNoiseOptions::Check() const {
  CheckOption(std::abs(wheel_radius_error) < 0.5, "odometry.wheel_radius_error",
              "must be within +-0.5");
  CheckOption(std::abs(yaw_scale_error) < 0.5, "odometry.yaw_scale_error",
              "must be within +-0.5");
  CheckOption(translation_noise >= 0 && translation_noise < 1.0,
              "odometry.translation_noise", "must be in [0, 1)");
  CheckOption(rotation_noise_per_meter >= 0 && rotation_noise_per_meter < 1.0,
              "odometry.rotation_noise_per_meter", "must be in [0, 1)");
  CheckOption(rotation_noise_per_radian >= 0 && rotation_noise_per_radian < 1.0,
              "odometry.rotation_noise_per_radian", "must be in [0, 1)");
}

std::vector<TimedPose2d> SimulateOdometry(const std::vector<TimedPose2d>& truth,
                                          const OdometryNoiseOptions& options,
                                          uint64_t seed) {
  options.Check();
  std::vector<TimedPose2d> odom;
  if (truth.empty()) return odom;
  cv::RNG rng(SimMixSeed(seed, options.seed));
  odom.push_back(truth[0]);
  double x = truth[0].pose.x, y = truth[0].pose.y, yaw = truth[0].pose.yaw;
  for (size_t k = 1; k < truth.size(); ++k) {
    const Pose2d& a = truth[k - 1].pose;
    const Pose2d& b = truth[k].pose;
    // True increment in the frame of the previous base pose.
    Vector2d dp = Rot2(-a.yaw) * Vector2d(b.x - a.x, b.y - a.y);
    double dyaw = WrapAngle(b.yaw - a.yaw);
    const double dist = dp.norm();
    // Noise is drawn every step (even at zero sigma) so the random stream
    // does not depend on the options' values.
    const double n_t = rng.gaussian(1.0);
    const double n_r = rng.gaussian(1.0);
    Vector2d dir = dist > 0 ? Vector2d(dp / dist) : Vector2d(1.0, 0.0);
    dp = dp * (1.0 + options.wheel_radius_error) +
         dir * (options.translation_noise * std::sqrt(dist) * n_t);
    const double rot_sigma =
        std::sqrt(options.rotation_noise_per_meter *
                      options.rotation_noise_per_meter * dist +
                  options.rotation_noise_per_radian *
                      options.rotation_noise_per_radian * std::abs(dyaw));
    dyaw = dyaw * (1.0 + options.yaw_scale_error) + rot_sigma * n_r;
    const Vector2d step = Rot2(yaw) * dp;
    x += step.x();
    y += step.y();
    yaw = WrapAngle(yaw + dyaw);
    odom.push_back({truth[k].timestamp, Pose2d{x, y, yaw}});
  }
  return odom;
}

double PathLength(const std::vector<TimedPose2d>& poses) {
  double len = 0.0;
  for (size_t k = 1; k < poses.size(); ++k) {
    len += std::hypot(poses[k].pose.x - poses[k - 1].pose.x,
                      poses[k].pose.y - poses[k - 1].pose.y);
  }
  return len;
}

}  // namespace monomap
