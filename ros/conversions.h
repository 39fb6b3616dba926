// Conversions between ROS 1 messages and the localization session's types,
// kept apart from the node so that they are tested without a ROS master.
// Frames: map (the monomap map's world), odom, base (the robot's
// base_link), cam (the camera's optical frame).
#pragma once

#include <geometry_msgs/Pose.h>
#include <geometry_msgs/PoseArray.h>
#include <geometry_msgs/PoseWithCovariance.h>
#include <geometry_msgs/Transform.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>

#include <deque>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "monomap/camera/camera.h"
#include "monomap/geometry/pose2d.h"
#include "monomap/geometry/rigid3.h"
#include "monomap/localization/particle_filter.h"
#include "monomap/localization/session.h"

namespace monomap::ros_adapter {

// sensor_msgs/Image -> 8-bit gray (mono8) or BGR (bgr8, rgb8), a copy.
// Throws InputError naming the encoding or the size that does not fit.
cv::Mat ImageFromMsg(const sensor_msgs::Image& msg);
// sensor_msgs/CompressedImage (JPEG, PNG) -> BGR or gray. Throws InputError
// if it does not decode.
cv::Mat ImageFromMsg(const sensor_msgs::CompressedImage& msg);

// Why `info` does not describe `camera` (size differs, or fx, fy, cx, cy
// differ by more than `tolerance_px`); empty when it does.
std::string CameraInfoMismatch(const sensor_msgs::CameraInfo& info,
                               const Camera& camera, double tolerance_px);

Rigid3d RigidFromMsg(const geometry_msgs::Pose& msg);
Rigid3d RigidFromMsg(const geometry_msgs::Transform& msg);
geometry_msgs::Pose PoseMsg(const Rigid3d& pose);
geometry_msgs::Transform TransformMsg(const Rigid3d& pose);
// Row-major 6x6, as PoseWithCovariance::covariance.
boost::array<double, 36> CovarianceMsg(const Eigen::Matrix<double, 6, 6>& c);

// The planar pose (x, y, yaw) of a base pose in the odom frame.
Pose2d PlanarPose(const Rigid3d& odom_from_base);

// world_from_odom = world_from_base * odom_from_base^-1: the map -> odom
// transform that makes odom -> base end at the estimated base pose.
Rigid3d WorldFromOdom(const Rigid3d& world_from_base,
                      const Rigid3d& odom_from_base);

// The session frame of an image with its odometry and camera mount.
SessionFrame MakeFrame(double stamp, cv::Mat image,
                       const Rigid3d& odom_from_base,
                       const Rigid3d& base_from_cam);

// rviz's "2D Pose Estimate" as a session request: the base pose becomes a
// camera pose through the mount; the spreads are the standard deviations
// of x, y and yaw in the covariance (empty when the covariance is zero:
// the session's defaults apply).
struct PoseRequest {
  Rigid3d world_from_cam;
  std::optional<double> spread_m, spread_deg;
};
PoseRequest InitialPoseRequest(const geometry_msgs::PoseWithCovariance& msg,
                               const Rigid3d& base_from_cam);

// The particles as base poses (camera poses without a mount).
std::vector<geometry_msgs::Pose> ParticlePoses(
    const std::vector<Particle>& particles,
    const std::optional<Rigid3d>& base_from_cam);

// A short history of odom_from_base, interpolated at image stamps.
class OdometryBuffer {
 public:
  // Samples older than the newest by more than `span_s` are forgotten.
  explicit OdometryBuffer(double span_s) : span_s_(span_s) {}
  // Adds a sample; returns false (and ignores it) if its stamp is not
  // later than the newest one's.
  bool Add(double stamp, const Rigid3d& odom_from_base);
  // The pose at `stamp`, interpolated between the two samples around it if
  // they are at most `max_gap_s` apart; empty outside the history.
  std::optional<Rigid3d> At(double stamp, double max_gap_s) const;
  // The newest sample's stamp (empty before the first).
  std::optional<double> newest_stamp() const;
  void Clear() { samples_.clear(); }

 private:
  double span_s_;
  std::deque<std::pair<double, Rigid3d>> samples_;
};

}  // namespace monomap::ros_adapter
