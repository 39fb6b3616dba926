// Imports a ROS 1 bag (read with Debian's librosbag-dev) into a dataset in
// monomap's layout (docs/dataset-format.md, docs/importing.md):
//   images       sensor_msgs/Image (mono8, bgr8, rgb8) or CompressedImage
//   calibration  sensor_msgs/CameraInfo (plumb_bob)
//   odometry     nav_msgs/Odometry, or tf2_msgs/TFMessage odom -> base_link
//   mount        /tf_static base_link -> camera frame (or a mount file)
// Odometry is interpolated to the image stamps (slerp on rotation); images
// outside the odometry, or in a gap of it, are dropped and counted.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "monomap/camera/camera.h"
#include "monomap/geometry/rigid3.h"

namespace monomap {

struct RosbagImportOptions {
  // Topic of sensor_msgs/Image or sensor_msgs/CompressedImage messages.
  std::string image_topic;
  // Topic of sensor_msgs/CameraInfo messages (the first one is used).
  std::string camera_info_topic;
  // Topic of nav_msgs/Odometry messages; empty: use odom_tf instead.
  std::string odom_topic;
  // "PARENT:CHILD" frames of the odometry transform on tf_topic, e.g.
  // "odom:base_link"; used when odom_topic is empty.
  std::string odom_tf;
  // Topics of dynamic and static transforms.
  std::string tf_topic = "/tf";
  std::string tf_static_topic = "/tf_static";
  // Robot base frame the mount is relative to; empty: the odometry's child
  // frame.
  std::string base_frame;
  // Camera frame; empty: the images' header.frame_id.
  std::string camera_frame;
  // camera_mount.yaml (any form of io/camera_mount.h) to use instead of
  // /tf_static; required when the bag has no base -> camera transform.
  std::filesystem::path camera_mount;
  // Largest time gap (s) between the two odometry samples around an image;
  // images in larger gaps are dropped (counted), never extrapolated.
  double max_odometry_gap = 0.5;
  // The base counts as planar (odometry2d.txt is written too) if it never
  // tilts more than this (degrees) ...
  double max_planar_tilt_deg = 2.0;
  // ... nor leaves the floor by more than this (m).
  double max_planar_height_m = 0.05;

  void Check() const;
};

struct RosbagImportReport {
  int images_in_bag = 0;
  int frames_written = 0;
  // Images before the first or after the last odometry sample.
  int dropped_outside_odometry = 0;
  // Images inside the span but in a gap larger than max_odometry_gap.
  int dropped_in_gap = 0;
  int odometry_samples = 0;
  double odometry_start = 0.0, odometry_end = 0.0;
  std::string image_encoding;  // e.g. "mono8" or "compressed jpeg"
  Camera camera;
  Rigid3d base_from_cam;
  // Where the mount came from, e.g. "/tf_static base_link -> camera".
  std::string mount_source;
  // odometry2d.txt and camera_mount.yaml were written.
  bool planar = false;
};

// Reads `bag` and writes the dataset to `out_dir` atomically (replacing it
// only on success). Throws InputError naming the bag and the topic or field
// for a missing topic (listing the topics the bag has), a truncated or
// unreadable bag, an unsupported encoding or lens model, a missing
// calibration or mount; nothing is written then.
RosbagImportReport ImportRosbag(const std::filesystem::path& bag,
                                const std::filesystem::path& out_dir,
                                const RosbagImportOptions& options);

}  // namespace monomap
