// Test helper: builds ROS 1 messages for bags that tests write with
// rosbag::Bag (the importer's tests generate their own bags), and the sink
// of bag_test::LogDrive that writes them.
#pragma once

#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <tf2_msgs/TFMessage.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "monomap/camera/camera.h"
#include "monomap/geometry/rigid3.h"

namespace monomap::rosbag_test {

inline sensor_msgs::CameraInfo CameraInfoMsg(const Camera& c,
                                             const std::string& frame,
                                             double stamp) {
  sensor_msgs::CameraInfo m;
  m.header.stamp = ros::Time(stamp);
  m.header.frame_id = frame;
  m.width = c.width;
  m.height = c.height;
  m.distortion_model = LensModelName(c.model);
  // equidistant has k1..k4, plumb_bob k1 k2 p1 p2 k3.
  m.D.assign(
      c.distortion.begin(),
      c.distortion.begin() + (c.model == LensModel::kEquidistant ? 4 : 5));
  m.K = {c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1};
  m.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  m.P = {c.fx, 0, c.cx, 0, 0, c.fy, c.cy, 0, 0, 0, 1, 0};
  return m;
}

// `image` is 8-bit grey (mono8) or BGR (bgr8, or rgb8 after swapping).
inline sensor_msgs::Image ImageMsg(const cv::Mat& image,
                                   const std::string& encoding,
                                   const std::string& frame, double stamp) {
  sensor_msgs::Image m;
  m.header.stamp = ros::Time(stamp);
  m.header.frame_id = frame;
  m.width = image.cols;
  m.height = image.rows;
  m.encoding = encoding;
  m.step = image.cols * image.elemSize();
  cv::Mat pixels = image;
  if (encoding == "rgb8") cv::cvtColor(image, pixels, cv::COLOR_BGR2RGB);
  pixels = pixels.isContinuous() ? pixels : pixels.clone();
  m.data.assign(pixels.data, pixels.data + m.step * m.height);
  return m;
}

inline sensor_msgs::CompressedImage CompressedMsg(const cv::Mat& image,
                                                  const std::string& ext,
                                                  const std::string& frame,
                                                  double stamp) {
  sensor_msgs::CompressedImage m;
  m.header.stamp = ros::Time(stamp);
  m.header.frame_id = frame;
  m.format = ext == ".png" ? "png" : "jpeg";
  cv::imencode(ext, image, m.data);
  return m;
}

inline geometry_msgs::Transform TransformMsg(const Rigid3d& t) {
  geometry_msgs::Transform m;
  m.translation.x = t.translation.x();
  m.translation.y = t.translation.y();
  m.translation.z = t.translation.z();
  m.rotation.x = t.rotation.x();
  m.rotation.y = t.rotation.y();
  m.rotation.z = t.rotation.z();
  m.rotation.w = t.rotation.w();
  return m;
}

inline nav_msgs::Odometry OdometryMsg(const Rigid3d& odom_from_base,
                                      const std::string& odom,
                                      const std::string& base, double stamp) {
  nav_msgs::Odometry m;
  m.header.stamp = ros::Time(stamp);
  m.header.frame_id = odom;
  m.child_frame_id = base;
  const geometry_msgs::Transform t = TransformMsg(odom_from_base);
  m.pose.pose.position.x = t.translation.x;
  m.pose.pose.position.y = t.translation.y;
  m.pose.pose.position.z = t.translation.z;
  m.pose.pose.orientation = t.rotation;
  return m;
}

inline tf2_msgs::TFMessage TfMsg(const Rigid3d& parent_from_child,
                                 const std::string& parent,
                                 const std::string& child, double stamp) {
  geometry_msgs::TransformStamped t;
  t.header.stamp = ros::Time(stamp);
  t.header.frame_id = parent;
  t.child_frame_id = child;
  t.transform = TransformMsg(parent_from_child);
  tf2_msgs::TFMessage m;
  m.transforms.push_back(t);
  return m;
}

// bag_test::LogDrive into a ROS 1 bag.
class Ros1Sink {
 public:
  explicit Ros1Sink(const std::filesystem::path& path)
      : bag_(path.string(), rosbag::bagmode::Write) {}
  void CameraInfo(const std::string& topic, double t, const Camera& c,
                  const std::string& model, bool calibrated) {
    auto info = CameraInfoMsg(c, "camera_optical", t);
    info.distortion_model = model;
    if (!calibrated) info.K.fill(0.0);
    bag_.write(topic, ros::Time(t), info);
  }
  void Tf(const std::string& topic, double recorded, double stamp,
          const std::string& parent, const std::string& child,
          const Rigid3d& parent_from_child) {
    bag_.write(topic, ros::Time(recorded),
               TfMsg(parent_from_child, parent, child, stamp));
  }
  void Odometry(const std::string& topic, double t, const std::string& parent,
                const std::string& child, const Rigid3d& odom_from_base) {
    bag_.write(topic, ros::Time(t),
               OdometryMsg(odom_from_base, parent, child, t));
  }
  void Image(const std::string& topic, double t, const std::string& frame,
             const cv::Mat& image, const std::string& encoding) {
    bag_.write(topic, ros::Time(t), ImageMsg(image, encoding, frame, t));
  }
  void Compressed(const std::string& topic, double t, const std::string& frame,
                  const cv::Mat& image, const std::string& ext) {
    bag_.write(topic, ros::Time(t), CompressedMsg(image, ext, frame, t));
  }

 private:
  rosbag::Bag bag_;
};

}  // namespace monomap::rosbag_test
