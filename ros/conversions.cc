#include "ros/conversions.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "monomap/io/ros_image.h"
#include "monomap/util/error.h"

namespace monomap::ros_adapter {

cv::Mat ImageFromMsg(const sensor_msgs::Image& msg) {
  return PixelsOfImageMsg(msg, "sensor_msgs/Image");
}

cv::Mat ImageFromMsg(const sensor_msgs::CompressedImage& msg) {
  cv::Mat image;
  if (!msg.data.empty()) {
    image = cv::imdecode(cv::Mat(1, int(msg.data.size()), CV_8UC1,
                                 const_cast<uint8_t*>(msg.data.data())),
                         cv::IMREAD_UNCHANGED);
  }
  if (image.empty() || image.depth() != CV_8U ||
      (image.channels() != 1 && image.channels() != 3)) {
    throw InputError("sensor_msgs/CompressedImage", "data",
                     "does not decode to an 8-bit gray or color image "
                     "(format '" + msg.format + "')");
  }
  return image;
}

std::string CameraInfoMismatch(const sensor_msgs::CameraInfo& info,
                               const Camera& camera, double tolerance_px) {
  if (int(info.width) != camera.width || int(info.height) != camera.height) {
    return "size " + std::to_string(info.width) + "x" +
           std::to_string(info.height) + " differs from the map camera's " +
           std::to_string(camera.width) + "x" + std::to_string(camera.height);
  }
  const double k[4] = {info.K[0], info.K[4], info.K[2], info.K[5]};
  const double c[4] = {camera.fx, camera.fy, camera.cx, camera.cy};
  const char* names[4] = {"fx", "fy", "cx", "cy"};
  for (int i = 0; i < 4; ++i) {
    if (!(std::abs(k[i] - c[i]) <= tolerance_px)) {
      return std::string("K's ") + names[i] + " " + std::to_string(k[i]) +
             " differs from the map camera's " + std::to_string(c[i]) +
             " by more than " + std::to_string(tolerance_px) + " px";
    }
  }
  return "";
}

Rigid3d RigidFromMsg(const geometry_msgs::Pose& msg) {
  return Rigid3d(Eigen::Quaterniond(msg.orientation.w, msg.orientation.x,
                                    msg.orientation.y, msg.orientation.z)
                     .normalized(),
                 Eigen::Vector3d(msg.position.x, msg.position.y,
                                 msg.position.z));
}

Rigid3d RigidFromMsg(const geometry_msgs::Transform& msg) {
  return Rigid3d(Eigen::Quaterniond(msg.rotation.w, msg.rotation.x,
                                    msg.rotation.y, msg.rotation.z)
                     .normalized(),
                 Eigen::Vector3d(msg.translation.x, msg.translation.y,
                                 msg.translation.z));
}

geometry_msgs::Pose PoseMsg(const Rigid3d& pose) {
  geometry_msgs::Pose m;
  m.position.x = pose.translation.x();
  m.position.y = pose.translation.y();
  m.position.z = pose.translation.z();
  m.orientation.x = pose.rotation.x();
  m.orientation.y = pose.rotation.y();
  m.orientation.z = pose.rotation.z();
  m.orientation.w = pose.rotation.w();
  return m;
}

geometry_msgs::Transform TransformMsg(const Rigid3d& pose) {
  const geometry_msgs::Pose p = PoseMsg(pose);
  geometry_msgs::Transform m;
  m.translation.x = p.position.x;
  m.translation.y = p.position.y;
  m.translation.z = p.position.z;
  m.rotation = p.orientation;
  return m;
}

boost::array<double, 36> CovarianceMsg(const Eigen::Matrix<double, 6, 6>& c) {
  boost::array<double, 36> m;
  for (int r = 0; r < 6; ++r) {
    for (int col = 0; col < 6; ++col) m[6 * r + col] = c(r, col);
  }
  return m;
}

Pose2d PlanarPose(const Rigid3d& odom_from_base) {
  const Eigen::Vector3d x_axis = odom_from_base.rotation * Eigen::Vector3d::UnitX();
  return Pose2d{odom_from_base.translation.x(), odom_from_base.translation.y(),
                std::atan2(x_axis.y(), x_axis.x())};
}

Rigid3d WorldFromOdom(const Rigid3d& world_from_base,
                      const Rigid3d& odom_from_base) {
  return world_from_base * odom_from_base.Inverse();
}

SessionFrame MakeFrame(double stamp, cv::Mat image,
                       const Rigid3d& odom_from_base,
                       const Rigid3d& base_from_cam) {
  SessionFrame f;
  f.stamp = stamp;
  f.image = std::move(image);
  f.odom_from_cam = odom_from_base * base_from_cam;
  f.odom_base = PlanarPose(odom_from_base);
  return f;
}

PoseRequest InitialPoseRequest(const geometry_msgs::PoseWithCovariance& msg,
                               const Rigid3d& base_from_cam) {
  PoseRequest r;
  r.world_from_cam = RigidFromMsg(msg.pose) * base_from_cam;
  // x, y and yaw (row-major indices 0, 7, 35), as rviz sets them.
  const double var_xy = 0.5 * (msg.covariance[0] + msg.covariance[7]);
  const double var_yaw = msg.covariance[35];
  if (var_xy > 0.0) r.spread_m = std::sqrt(var_xy);
  if (var_yaw > 0.0) r.spread_deg = std::sqrt(var_yaw) * 180.0 / M_PI;
  return r;
}

std::vector<geometry_msgs::Pose> ParticlePoses(
    const std::vector<Particle>& particles,
    const std::optional<Rigid3d>& base_from_cam) {
  const Rigid3d cam_from_base =
      base_from_cam ? base_from_cam->Inverse() : Rigid3d::Identity();
  std::vector<geometry_msgs::Pose> poses;
  poses.reserve(particles.size());
  for (const Particle& p : particles) {
    poses.push_back(PoseMsg(p.world_from_cam * cam_from_base));
  }
  return poses;
}

bool OdometryBuffer::Add(double stamp, const Rigid3d& odom_from_base) {
  if (!samples_.empty() && stamp <= samples_.back().first) return false;
  samples_.emplace_back(stamp, odom_from_base);
  while (samples_.front().first < stamp - span_s_) samples_.pop_front();
  return true;
}

std::optional<Rigid3d> OdometryBuffer::At(double stamp,
                                          double max_gap_s) const {
  // The first sample not before `stamp`.
  const auto after = std::lower_bound(
      samples_.begin(), samples_.end(), stamp,
      [](const auto& sample, double t) { return sample.first < t; });
  if (after == samples_.end()) return std::nullopt;
  if (after->first == stamp) return after->second;
  if (after == samples_.begin()) return std::nullopt;
  const auto before = std::prev(after);
  const double gap = after->first - before->first;
  if (gap > max_gap_s) return std::nullopt;
  return Interpolate(before->second, after->second,
                     (stamp - before->first) / gap);
}

std::optional<double> OdometryBuffer::newest_stamp() const {
  if (samples_.empty()) return std::nullopt;
  return samples_.back().first;
}

}  // namespace monomap::ros_adapter
