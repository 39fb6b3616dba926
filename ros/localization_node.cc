#include "ros/localization_node.h"

#include <geometry_msgs/PoseArray.h>
#include <geometry_msgs/TransformStamped.h>
#include <std_msgs/String.h>

#include <utility>

#include "monomap/util/error.h"

namespace monomap::ros_adapter {
namespace {

// tf frame ids may carry a leading '/' (tf1 style).
std::string Bare(const std::string& frame) {
  return !frame.empty() && frame[0] == '/' ? frame.substr(1) : frame;
}

}  // namespace

LocalizationNode::LocalizationNode(ros::NodeHandle nh, ros::NodeHandle pnh,
                                   const NodeOptions& options,
                                   std::shared_ptr<const Map> map)
    : options_(options),
      map_(std::move(map)),
      tf_listener_(tf_buffer_),
      base_from_cam_(options.base_from_cam),
      odometry_(options.odom_buffer_s) {
  pose_pub_ =
      nh.advertise<geometry_msgs::PoseWithCovarianceStamped>("amcl_pose", 2,
                                                             true);
  particles_pub_ = nh.advertise<geometry_msgs::PoseArray>("particlecloud", 2);
  status_pub_ = pnh.advertise<std_msgs::String>("status", 10, true);
  if (options_.compressed) {
    image_sub_ = nh.subscribe("image/compressed", 2,
                              &LocalizationNode::OnCompressedImage, this);
  } else {
    image_sub_ = nh.subscribe("image", 2, &LocalizationNode::OnImage, this);
  }
  info_sub_ = nh.subscribe("camera_info", 2, &LocalizationNode::OnCameraInfo,
                           this);
  if (options_.odom_source == "odom") {
    odom_sub_ = nh.subscribe("odom", 100, &LocalizationNode::OnOdometry, this);
  } else {
    odom_sub_ = nh.subscribe("/tf", 100, &LocalizationNode::OnTf, this);
  }
  initial_pose_sub_ = nh.subscribe("initialpose", 2,
                                   &LocalizationNode::OnInitialPose, this);
  global_service_ = nh.advertiseService(
      "global_localization", &LocalizationNode::OnGlobalLocalization, this);
  PublishStatus("waiting", {});
  if (!options_.camera_frame.empty() || options_.base_from_cam) {
    start_timer_ = nh.createWallTimer(ros::WallDuration(0.1), [this](const auto&) {
      std::lock_guard<std::mutex> lock(mutex_);
      if (EnsureSession(options_.camera_frame)) start_timer_.stop();
    });
  }
}

LocalizationNode::~LocalizationNode() {
  std::unique_ptr<LocalizationSession> session;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    session = std::move(session_);
  }
  if (session) session->Stop();
}

void LocalizationNode::OnImage(const sensor_msgs::ImageConstPtr& msg) {
  try {
    OnImageDecoded(msg->header, ImageFromMsg(*msg));
  } catch (const InputError& e) {
    ROS_ERROR_THROTTLE(5.0, "%s: %s", image_sub_.getTopic().c_str(), e.what());
  }
}

void LocalizationNode::OnCompressedImage(
    const sensor_msgs::CompressedImageConstPtr& msg) {
  try {
    OnImageDecoded(msg->header, ImageFromMsg(*msg));
  } catch (const InputError& e) {
    ROS_ERROR_THROTTLE(5.0, "%s: %s", image_sub_.getTopic().c_str(), e.what());
  }
}

void LocalizationNode::OnImageDecoded(const std_msgs::Header& header,
                                      cv::Mat image) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (disabled_ || !EnsureSession(Bare(header.frame_id))) return;
  if (pending_) {
    ++skipped_;  // a newer image replaces one still waiting for odometry
    ROS_WARN_THROTTLE(5.0, "image at %.3f skipped: no odometry at its stamp "
                      "before the next image",
                      pending_->stamp);
  }
  pending_ = PendingImage{header.stamp.toSec(), std::move(image),
                          ros::WallTime::now()};
  TryPush();
}

bool LocalizationNode::EnsureSession(const std::string& camera_frame) {
  if (session_) return true;
  if (!base_from_cam_) {
    try {
      base_from_cam_ = RigidFromMsg(
          tf_buffer_
              .lookupTransform(options_.base_frame, camera_frame, ros::Time(0))
              .transform);
    } catch (const tf2::TransformException& e) {
      ROS_WARN_THROTTLE(5.0, "waiting for the camera mount %s -> %s on tf: %s",
                        options_.base_frame.c_str(), camera_frame.c_str(),
                        e.what());
      return false;
    }
  }
  session_ = std::make_unique<LocalizationSession>(
      map_, map_->camera, options_.session, base_from_cam_);
  if (pending_request_) {
    session_->SetPose(pending_request_->world_from_cam,
                      pending_request_->spread_m, pending_request_->spread_deg);
  }
  if (pending_global_) session_->StartGlobalLocalization();
  session_->Start([this](const SessionResult& r) { OnResult(r); });
  ROS_INFO("localizing with camera mount %s -> %s", options_.base_frame.c_str(),
           camera_frame.c_str());
  PublishStatus("ready", {});
  return true;
}

void LocalizationNode::TryPush() {
  if (!pending_ || !session_) return;
  const std::optional<Rigid3d> odom_from_base =
      odometry_.At(pending_->stamp, options_.odom_max_gap_s);
  if (!odom_from_base) {
    const std::optional<double> newest = odometry_.newest_stamp();
    const bool may_come =
        !newest || *newest < pending_->stamp;  // odometry lags the image
    if (may_come && (ros::WallTime::now() - pending_->arrived).toSec() <
                        options_.odom_wait_s) {
      return;  // wait for the next odometry message
    }
    ++skipped_;
    ROS_WARN_THROTTLE(5.0, "image at %.3f skipped: no odometry at its stamp "
                      "(%s)", pending_->stamp,
                      newest ? ("newest odometry at " +
                                std::to_string(*newest)).c_str()
                             : "no odometry received");
    pending_.reset();
    return;
  }
  const PushOutcome outcome = session_->Push(MakeFrame(
      pending_->stamp, std::move(pending_->image), *odom_from_base,
      *base_from_cam_));
  pending_.reset();
  if (!outcome.accepted) {
    ++rejected_;
    ROS_WARN_THROTTLE(5.0, "image rejected: %s", outcome.reason.c_str());
  }
}

void LocalizationNode::OnCameraInfo(const sensor_msgs::CameraInfoConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (camera_info_checked_ || disabled_) return;
  const std::string why = CameraInfoMismatch(*msg, map_->camera,
                                             options_.camera_info_tolerance_px);
  if (!why.empty()) {
    ROS_ERROR("%s: %s; not localizing (the map was built with another "
              "camera, or the wrong camera_info topic is remapped)",
              info_sub_.getTopic().c_str(), why.c_str());
    disabled_ = true;
    pending_.reset();
    PublishStatus("camera_info_mismatch",
                  session_ ? session_->counters() : SessionCounters());
    return;
  }
  camera_info_checked_ = true;
  ROS_INFO("%s matches the map's camera", info_sub_.getTopic().c_str());
}

void LocalizationNode::OnOdometry(const nav_msgs::OdometryConstPtr& msg) {
  AddOdometry(msg->header.stamp.toSec(), RigidFromMsg(msg->pose.pose));
}

void LocalizationNode::OnTf(const tf2_msgs::TFMessageConstPtr& msg) {
  for (const geometry_msgs::TransformStamped& t : msg->transforms) {
    if (Bare(t.header.frame_id) == options_.odom_frame &&
        Bare(t.child_frame_id) == options_.base_frame) {
      AddOdometry(t.header.stamp.toSec(), RigidFromMsg(t.transform));
    }
  }
}

void LocalizationNode::AddOdometry(double stamp,
                                   const Rigid3d& odom_from_base) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!odometry_.Add(stamp, odom_from_base)) {
    ROS_WARN_THROTTLE(5.0, "odometry at %.3f ignored: not later than the "
                      "previous sample", stamp);
    return;
  }
  TryPush();
}

void LocalizationNode::OnInitialPose(
    const geometry_msgs::PoseWithCovarianceStampedConstPtr& msg) {
  if (Bare(msg->header.frame_id) != options_.global_frame) {
    ROS_WARN("initial pose ignored: in frame '%s', not '%s'",
             msg->header.frame_id.c_str(), options_.global_frame.c_str());
    return;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  if (!base_from_cam_) {  // the mount comes with the first image
    pending_request_ = InitialPoseRequest(msg->pose, Rigid3d::Identity());
    ROS_WARN("initial pose kept until the camera mount is known");
    return;
  }
  const PoseRequest r = InitialPoseRequest(msg->pose, *base_from_cam_);
  ROS_INFO("initial pose (%.3f, %.3f), spread %.3f m / %.1f deg",
           msg->pose.pose.position.x, msg->pose.pose.position.y,
           r.spread_m.value_or(options_.session.localizer.init.spread_m),
           r.spread_deg.value_or(options_.session.localizer.init.spread_deg));
  if (session_) {
    session_->SetPose(r.world_from_cam, r.spread_m, r.spread_deg);
  } else {
    pending_request_ = r;
  }
}

bool LocalizationNode::OnGlobalLocalization(std_srvs::Empty::Request&,
                                            std_srvs::Empty::Response&) {
  std::lock_guard<std::mutex> lock(mutex_);
  ROS_INFO("global localization requested");
  if (session_) {
    session_->StartGlobalLocalization();
  } else {
    pending_global_ = true;
  }
  return true;
}

void LocalizationNode::OnResult(const SessionResult& r) {
  const ros::Time stamp(r.stamp);
  const Rigid3d cam_from_base = base_from_cam_->Inverse();
  const Rigid3d world_from_base =
      r.world_from_base.value_or(r.world_from_cam * cam_from_base);
  const Rigid3d odom_from_base = r.odom_from_cam * cam_from_base;

  geometry_msgs::PoseWithCovarianceStamped pose;
  pose.header.stamp = stamp;
  pose.header.frame_id = options_.global_frame;
  pose.pose.pose = PoseMsg(world_from_base);
  pose.pose.covariance = CovarianceMsg(r.covariance);
  pose_pub_.publish(pose);

  // Future-dated as AMCL does, so that lookups up to now + tolerance work.
  geometry_msgs::TransformStamped tf;
  tf.header.stamp = stamp + ros::Duration(options_.transform_tolerance);
  tf.header.frame_id = options_.global_frame;
  tf.child_frame_id = options_.odom_frame;
  tf.transform = TransformMsg(WorldFromOdom(world_from_base, odom_from_base));
  tf_broadcaster_.sendTransform(tf);

  if (options_.session.output_particles) {
    geometry_msgs::PoseArray cloud;
    cloud.header = pose.header;
    cloud.poses = ParticlePoses(r.particles, base_from_cam_);
    particles_pub_.publish(cloud);
  }
  SessionCounters c;
  c.dropped = r.frames_dropped;
  c.processed = r.frames_processed;
  PublishStatus(ToString(r.status), c);
}

void LocalizationNode::PublishStatus(const std::string& status,
                                     const SessionCounters& c) {
  std_msgs::String msg;
  msg.data = status + " processed=" + std::to_string(c.processed) +
             " dropped=" + std::to_string(c.dropped) +
             " rejected=" + std::to_string(rejected_.load()) +
             " skipped_no_odometry=" + std::to_string(skipped_.load());
  status_pub_.publish(msg);
  std::lock_guard<std::mutex> lock(status_mutex_);
  if (status != last_status_) {
    ROS_INFO("status: %s", status.c_str());
    last_status_ = status;
  }
}

}  // namespace monomap::ros_adapter
