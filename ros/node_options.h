// The node's ROS private parameters, read into the session's options. The
// filter parameters mirror `monomap localize`'s options and bind to the
// same LocalizerOptions fields; a parameter left unset keeps the struct's
// default.
#pragma once

#include <ros/node_handle.h>

#include <optional>
#include <string>

#include "monomap/geometry/rigid3.h"
#include "monomap/localization/session.h"

namespace monomap::ros_adapter {

struct NodeOptions {
  // The map directory (`monomap build`'s output). Required.
  std::string map_dir;
  SessionOptions session;
  // "odom": nav_msgs/Odometry on the odom topic; "tf": odom -> base on /tf.
  std::string odom_source = "odom";
  // Subscribe to sensor_msgs/CompressedImage ("image/compressed") instead
  // of sensor_msgs/Image ("image").
  bool compressed = false;
  std::string global_frame = "map";
  std::string odom_frame = "odom";
  std::string base_frame = "base_link";
  // The camera mount; empty: looked up on tf (base -> the image's frame).
  std::optional<Rigid3d> base_from_cam;
  // The camera's tf frame. Set: the mount is looked up (and the session
  // started, which takes a while) before the first image, so that no
  // image is lost to the start; empty: the first image's frame.
  std::string camera_frame;
  // map -> odom is stamped this far after the image, as AMCL's
  // transform_tolerance (s).
  double transform_tolerance = 0.1;
  // camera_info's fx, fy, cx, cy may differ from the map camera's this
  // much (px).
  double camera_info_tolerance_px = 1.0;
  // Odometry kept for interpolation (s), and the largest gap between two
  // samples an image stamp is interpolated across (s).
  double odom_buffer_s = 5.0;
  double odom_max_gap_s = 0.5;
  // An image newer than the newest odometry waits for it this long (s).
  double odom_wait_s = 0.5;
};

// Reads the private parameters of `pnh`. Throws OptionsError naming the
// parameter that is missing or wrong.
NodeOptions ReadNodeOptions(const ros::NodeHandle& pnh);

}  // namespace monomap::ros_adapter
