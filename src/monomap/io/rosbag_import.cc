#include "monomap/io/rosbag_import.h"

#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <tf2_msgs/TFMessage.h>

#include "monomap/util/error.h"

namespace monomap {
namespace fs = std::filesystem;

namespace {

Rigid3d FromTransform(const geometry_msgs::Transform& t) {
  return Rigid3d(
      Eigen::Quaterniond(t.rotation.w, t.rotation.x, t.rotation.y,
                         t.rotation.z),
      Eigen::Vector3d(t.translation.x, t.translation.y, t.translation.z));
}

Rigid3d FromPose(const geometry_msgs::Pose& p) {
  return Rigid3d(Eigen::Quaterniond(p.orientation.w, p.orientation.x,
                                    p.orientation.y, p.orientation.z),
                 Eigen::Vector3d(p.position.x, p.position.y, p.position.z));
}

double Stamp(const ros::Time& header_stamp, const rosbag::MessageInstance& m) {
  // An unset header stamp falls back to the time the bag recorded.
  return header_stamp.isZero() ? m.getTime().toSec() : header_stamp.toSec();
}

// rosbag::Bag behind bag::BagMessages: instantiates the ROS 1 messages and
// copies the fields the importer reads.
class Ros1Messages : public bag::BagMessages {
 public:
  Ros1Messages(const rosbag::Bag& bag, std::string name)
      : bag_(bag), name_(std::move(name)) {}
  std::string Name() const override { return name_; }
  std::map<std::string, std::string> Topics() const override {
    std::map<std::string, std::string> types;
    rosbag::View all(bag_);
    for (const rosbag::ConnectionInfo* c : all.getConnections()) {
      types[c->topic] = c->datatype;
    }
    return types;
  }
  void ForEachImage(const std::string& topic,
                    const std::function<bool(bag::Image&)>& visit) override {
    rosbag::View view(bag_, rosbag::TopicQuery(topic));
    for (const rosbag::MessageInstance& m : view) {
      bag::Image image;
      if (const auto raw = m.instantiate<sensor_msgs::Image>()) {
        image.stamp = Stamp(raw->header.stamp, m);
        image.frame_id = raw->header.frame_id;
        image.encoding = raw->encoding;
        image.width = raw->width;
        image.height = raw->height;
        image.step = raw->step;
        image.data = raw->data;
      } else if (const auto c = m.instantiate<sensor_msgs::CompressedImage>()) {
        image.stamp = Stamp(c->header.stamp, m);
        image.frame_id = c->header.frame_id;
        image.compressed = true;
        image.encoding = c->format;
        image.data = c->data;
      } else {
        continue;
      }
      if (!visit(image)) return;
    }
  }
  void ForEachCameraInfo(
      const std::string& topic,
      const std::function<bool(const bag::CameraInfo&)>& visit) override {
    rosbag::View view(bag_, rosbag::TopicQuery(topic));
    for (const rosbag::MessageInstance& m : view) {
      const auto msg = m.instantiate<sensor_msgs::CameraInfo>();
      if (!msg) continue;
      bag::CameraInfo info;
      info.width = msg->width;
      info.height = msg->height;
      info.distortion_model = msg->distortion_model;
      info.d = msg->D;
      std::copy(msg->K.begin(), msg->K.end(), info.k.begin());
      if (!visit(info)) return;
    }
  }
  void ForEachTransform(
      const std::string& topic,
      const std::function<bool(const bag::Transform&)>& visit) override {
    rosbag::View view(bag_, rosbag::TopicQuery(topic));
    for (const rosbag::MessageInstance& m : view) {
      const auto msg = m.instantiate<tf2_msgs::TFMessage>();
      if (!msg) continue;
      for (const auto& t : msg->transforms) {
        if (!visit({Stamp(t.header.stamp, m), t.header.frame_id,
                    t.child_frame_id, FromTransform(t.transform)})) {
          return;
        }
      }
    }
  }
  void ForEachOdometry(
      const std::string& topic,
      const std::function<bool(const bag::Transform&)>& visit) override {
    rosbag::View view(bag_, rosbag::TopicQuery(topic));
    for (const rosbag::MessageInstance& m : view) {
      const auto msg = m.instantiate<nav_msgs::Odometry>();
      if (!msg) continue;
      if (!visit({Stamp(msg->header.stamp, m), msg->header.frame_id,
                  msg->child_frame_id, FromPose(msg->pose.pose)})) {
        return;
      }
    }
  }

 private:
  const rosbag::Bag& bag_;
  std::string name_;
};

}  // namespace

RosbagImportReport ImportRosbag(const fs::path& bag_path,
                                const fs::path& out_dir,
                                const RosbagImportOptions& options) {
  options.Check();
  if (!fs::is_regular_file(bag_path)) {
    throw InputError(bag_path.string() + ": bag file not found");
  }
  const std::string name = bag_path.string();
  try {
    rosbag::Bag bag;
    bag.open(name, rosbag::bagmode::Read);
    Ros1Messages messages(bag, name);
    return bag::ImportBag(messages, out_dir, options);
  } catch (const rosbag::BagException& e) {
    throw InputError(name +
                     ": cannot read the bag (truncated, unindexed "
                     "or not a ROS 1 bag; `rosbag reindex` may repair it): " +
                     e.what());
  } catch (const ros::Exception& e) {
    throw InputError(name + ": corrupt message: " + std::string(e.what()));
  }
}

}  // namespace monomap
