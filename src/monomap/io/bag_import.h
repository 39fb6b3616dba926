// The half of the ROS bag importers that does not depend on the bag format
// (docs/importing.md): ROS 1 bags (io/rosbag_import) and ROS 2 bags
// (io/rosbag2_import) decode their messages into the plain structs below
// and hand them over through a BagMessages reader; this file turns them
// into a dataset in monomap's layout:
//   images       sensor_msgs/Image (mono8, bgr8, rgb8) or CompressedImage
//   calibration  sensor_msgs/CameraInfo (plumb_bob or equidistant)
//   odometry     nav_msgs/Odometry, or tf2_msgs/TFMessage odom -> base_link
//   mount        /tf_static base_link -> camera frame (or a mount file)
// Odometry is interpolated to the image stamps (slerp on rotation); images
// outside the odometry, or in a gap of it, are dropped and counted.
// Kept C++17-clean: the ROS 1 reader includes it and builds as C++17.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

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

namespace bag {

// sensor_msgs/CameraInfo, the fields the importer reads.
struct CameraInfo {
  uint32_t width = 0, height = 0;
  std::string distortion_model;
  std::vector<double> d;
  std::array<double, 9> k{};  // row-major
};

// sensor_msgs/Image or sensor_msgs/CompressedImage.
struct Image {
  double stamp = 0;  // header stamp, or the recording time if unset
  std::string frame_id;
  bool compressed = false;
  std::string encoding;  // Image: "mono8", ...; CompressedImage: its format
  uint32_t width = 0, height = 0, step = 0;  // Image only
  std::vector<uint8_t> data;
};

// One transform of a tf2_msgs/TFMessage, or a nav_msgs/Odometry pose
// (parent = header.frame_id, child = child_frame_id).
struct Transform {
  double stamp = 0;  // header stamp, or the recording time if unset
  std::string parent, child;
  Rigid3d parent_from_child;
};

// A bag as the importer sees it; each bag format implements it. Readers
// throw InputError naming the bag and topic for a message they cannot
// decode.
class BagMessages {
 public:
  virtual ~BagMessages() = default;
  // The bag's path, for messages.
  virtual std::string Name() const = 0;
  // Topic -> message type as the bag names it ("sensor_msgs/Image" in ROS 1,
  // "sensor_msgs/msg/Image" in ROS 2).
  virtual std::map<std::string, std::string> Topics() const = 0;
  // Visitors over one topic's messages in bag order; `visit` returns false
  // to stop early.
  virtual void ForEachImage(const std::string& topic,
                            const std::function<bool(Image&)>& visit) = 0;
  virtual void ForEachCameraInfo(
      const std::string& topic,
      const std::function<bool(const CameraInfo&)>& visit) = 0;
  // Every transform of every tf2_msgs/TFMessage on the topic.
  virtual void ForEachTransform(
      const std::string& topic,
      const std::function<bool(const Transform&)>& visit) = 0;
  virtual void ForEachOdometry(
      const std::string& topic,
      const std::function<bool(const Transform&)>& visit) = 0;
};

// "pkg/msg/Name" (ROS 2) -> "pkg/Name" (ROS 1), to compare types.
std::string CanonicalType(const std::string& type);

// ROS camera_info -> Camera. Throws InputError naming `where` and the field
// for a missing calibration or an unsupported lens model.
Camera CameraFromInfo(const CameraInfo& info, const std::string& where);

// The pixels of a raw sensor_msgs/Image (mono8 -> 8-bit grey, bgr8 and
// rgb8 -> BGR), copied out of `data` (rows may be padded to `step`).
// Shared by the importers and the ROS node. Throws InputError naming
// `where` and the encoding, or the size that does not fit.
cv::Mat RawImagePixels(const std::string& encoding, uint32_t width,
                       uint32_t height, uint32_t step, const uint8_t* data,
                       size_t size, const std::string& where);

// Reads everything from `messages` and writes the dataset to `out_dir`
// atomically (replacing it only on success). Throws InputError naming the
// bag and the topic or field for a missing topic (listing the topics the
// bag has), an unsupported encoding or lens model, a missing calibration
// or mount; nothing is written then.
RosbagImportReport ImportBag(BagMessages& messages,
                             const std::filesystem::path& out_dir,
                             const RosbagImportOptions& options);

}  // namespace bag
}  // namespace monomap
