// A ground robot driving a smooth path through a World: true base poses,
// the camera mount, and wheel odometry with systematic and random errors.
// Base frame: x forward, y left, z up, origin on the floor. Camera frame:
// x right, y down, z forward.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "monomap/geometry/rigid3.h"
#include "monomap/geometry/pose2d.h"
#include "monomap/sim/world.h"

namespace monomap {

struct TimedPose2d {
  double timestamp = 0.0;
  Pose2d pose;
};

// Where the camera sits on the robot.
struct CameraMountOptions {
  // Height of the optical centre above the floor (m).
  double height_m = 0.5;
  // Offset of the optical centre ahead of the base origin (m).
  double forward_m = 0.1;
  // Downward tilt of the optical axis (degrees), so the floor is in view.
  double tilt_down_deg = 8.0;
  // Yaw of the optical axis to the left of the driving direction (degrees).
  double yaw_left_deg = 0.0;

  void Check() const;
};

// base_from_cam of the mount.
Rigid3d MakeCameraMount(const CameraMountOptions& options);

// How the robot drives along the world's path.
struct RobotPathOptions {
  // Constant forward speed (m/s).
  double speed_mps = 0.4;
  // Sample (odometry and camera) rate (Hz).
  double rate_hz = 30.0;
  // Timestamp of the first sample (s); TUM-like data starts far from 0.
  double start_time = 1000.0;
  // Start this far along the path (m, >= 0). An open path is then driven to
  // its end (the offset must be shorter than the path); a closed one is
  // still driven once around, wrapping past its first keypoint.
  double start_offset_m = 0.0;
  // Drive parallel to the path, this far to the left of the heading (m;
  // negative: to the right), at the same constant speed along the offset
  // curve. Must stay below the path's smallest turning radius on the inner
  // side (SampleRobotPath throws OptionsError otherwise).
  double lateral_offset_m = 0.0;

  void Check() const;
};

// A C1-smooth path through the keypoints (uniform Catmull-Rom spline,
// reparametrised by arc length). The heading follows the tangent, as for a
// differential-drive robot.
class RobotPath {
 public:
  // Throws OptionsError with fewer than 2 keypoints (3 for a loop).
  RobotPath(std::vector<Eigen::Vector2d> keypoints, bool closed);
  explicit RobotPath(const World& world)
      : RobotPath(world.path_keypoints, world.path_closed) {}

  double Length() const { return table_s_.back(); }
  bool closed() const { return closed_; }
  // Base pose after driving `s` metres (clamped to [0, Length()]).
  Pose2d PoseAt(double s) const;

 private:
  Eigen::Vector2d Point(double u, Eigen::Vector2d* tangent) const;
  std::vector<Eigen::Vector2d> ctrl_;  // with phantom/wrapped ends
  bool closed_ = false;
  int segments_ = 0;
  std::vector<double> table_u_, table_s_;  // arc-length table
};

// Samples the path at options.rate_hz and constant speed from
// options.start_offset_m to the end (loops are driven once), offset
// options.lateral_offset_m to the left. max_samples > 0 gives exactly that
// many samples: a loop is driven lap after lap; an open path too short for
// them throws OptionsError (with the most it holds). Also throws
// OptionsError if the start offset is not shorter than an open path, or if
// the lateral offset reaches a turn's centre (the offset curve would turn
// back on itself).
std::vector<TimedPose2d> SampleRobotPath(const RobotPath& path,
                                         const RobotPathOptions& options,
                                         int max_samples = -1);

// Wheel odometry errors of a differential-drive robot. Random errors are
// white per step with variance proportional to the step (a random walk), so
// the accumulated error does not depend on the sample rate.
struct OdometryNoiseOptions {
  // Relative error of the wheel radius: scales every distance.
  double wheel_radius_error = 0.01;
  // Relative error of the wheel base: scales every heading change.
  double yaw_scale_error = 0.01;
  // Random distance error (m per sqrt(m) driven).
  double translation_noise = 0.015;
  // Random heading error from driving (rad per sqrt(m) driven).
  double rotation_noise_per_meter = 0.007;
  // Random heading error from turning (rad per sqrt(rad) turned).
  double rotation_noise_per_radian = 0.02;
  // Seed of the random errors (mixed with the simulation seed).
  uint64_t seed = 7;

  // All errors zero: odometry equals ground truth.
  static OdometryNoiseOptions None();
  void Check() const;
};

// Integrates the true per-step increments with errors added, anchored at
// the true first pose. Deterministic given (options.seed, seed).
std::vector<TimedPose2d> SimulateOdometry(
    const std::vector<TimedPose2d>& truth,
    const OdometryNoiseOptions& options, uint64_t seed);

// Length of the polyline through the poses (m).
double PathLength(const std::vector<TimedPose2d>& poses);

}  // namespace monomap
