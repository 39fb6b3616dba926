// The ROS 1 node over a LocalizationSession, as AMCL with a camera instead
// of a laser: images + odometry in; the base pose with covariance, the
// particles and the tf map -> odom out; /initialpose and the
// global_localization service to (re)start the filter. Everything ROS is
// here; the session knows nothing of it.
#pragma once

#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <std_srvs/Empty.h>
#include <tf2_msgs/TFMessage.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_broadcaster.h>
#include <tf2_ros/transform_listener.h>

#include <atomic>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "monomap/map/map.h"
#include "ros/conversions.h"
#include "ros/node_options.h"

namespace monomap::ros_adapter {

class LocalizationNode {
 public:
  LocalizationNode(ros::NodeHandle nh, ros::NodeHandle pnh,
                   const NodeOptions& options, std::shared_ptr<const Map> map);
  ~LocalizationNode();  // stops the session's worker

 private:
  // An image waiting for odometry at its stamp.
  struct PendingImage {
    double stamp = 0.0;
    cv::Mat image;
    ros::WallTime arrived;
  };
  void OnImage(const sensor_msgs::ImageConstPtr& msg);
  void OnCompressedImage(const sensor_msgs::CompressedImageConstPtr& msg);
  void OnImageDecoded(const std_msgs::Header& header, cv::Mat image);
  void OnCameraInfo(const sensor_msgs::CameraInfoConstPtr& msg);
  void OnOdometry(const nav_msgs::OdometryConstPtr& msg);
  void OnTf(const tf2_msgs::TFMessageConstPtr& msg);
  void AddOdometry(double stamp, const Rigid3d& odom_from_base);
  void OnInitialPose(
      const geometry_msgs::PoseWithCovarianceStampedConstPtr& msg);
  bool OnGlobalLocalization(std_srvs::Empty::Request& request,
                            std_srvs::Empty::Response& response);
  // Starts the session once the camera mount is known.
  bool EnsureSession(const std::string& camera_frame);
  // Pushes the pending image if its odometry has come (or skips it).
  void TryPush();
  // On the session's worker thread.
  void OnResult(const SessionResult& result);
  // Any thread; `counters` as of the message.
  void PublishStatus(const std::string& status,
                     const SessionCounters& counters);

  NodeOptions options_;
  std::shared_ptr<const Map> map_;
  ros::Subscriber image_sub_, info_sub_, odom_sub_, initial_pose_sub_;
  ros::Publisher pose_pub_, particles_pub_, status_pub_;
  ros::ServiceServer global_service_;
  ros::WallTimer start_timer_;  // starts the session before any image
  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;
  tf2_ros::TransformBroadcaster tf_broadcaster_;

  // Callbacks run on the spinner thread; the session's results on its
  // worker. mutex_ guards what both touch.
  std::mutex mutex_;
  std::unique_ptr<LocalizationSession> session_;
  std::optional<Rigid3d> base_from_cam_;
  OdometryBuffer odometry_;
  std::optional<PendingImage> pending_;
  std::optional<PoseRequest> pending_request_;  // before the session starts
  bool pending_global_ = false;
  bool camera_info_checked_ = false;
  bool disabled_ = false;  // camera_info does not match: not localizing
  // Images without odometry at their stamp.
  std::atomic<int64_t> skipped_{0};
  std::atomic<int64_t> rejected_{0};  // refused by the session
  std::mutex status_mutex_;  // guards last_status_
  std::string last_status_;
};

}  // namespace monomap::ros_adapter
