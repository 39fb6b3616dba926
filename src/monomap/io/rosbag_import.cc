#include "monomap/io/rosbag_import.h"

#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <tf2_msgs/TFMessage.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>

#include "monomap/io/camera_mount.h"
#include "monomap/io/dataset_writer.h"
#include "monomap/io/ros_image.h"
#include "monomap/io/trajectory_io.h"
#include "monomap/util/error.h"
#include "monomap/util/file.h"

namespace monomap {
namespace fs = std::filesystem;

void RosbagImportOptions::Check() const {
  CheckOption(!image_topic.empty(), "rosbag.image_topic", "must be set");
  CheckOption(!camera_info_topic.empty(), "rosbag.camera_info_topic",
              "must be set");
  CheckOption(odom_topic.empty() != odom_tf.empty(), "rosbag.odom_topic",
              "set exactly one of odom_topic and odom_tf");
  CheckOption(
      odom_tf.empty() || (odom_tf.find(':') != std::string::npos &&
                          odom_tf.front() != ':' && odom_tf.back() != ':'),
      "rosbag.odom_tf", "must be PARENT:CHILD, e.g. odom:base_link");
  CheckOption(max_odometry_gap > 0, "rosbag.max_odometry_gap", "must be > 0");
  CheckOption(max_planar_tilt_deg >= 0, "rosbag.max_planar_tilt_deg",
              "must be >= 0");
  CheckOption(max_planar_height_m >= 0, "rosbag.max_planar_height_m",
              "must be >= 0");
}

namespace {

constexpr char kImage[] = "sensor_msgs/Image";
constexpr char kCompressed[] = "sensor_msgs/CompressedImage";
constexpr char kCameraInfo[] = "sensor_msgs/CameraInfo";
constexpr char kOdometry[] = "nav_msgs/Odometry";
constexpr char kTf[] = "tf2_msgs/TFMessage";

// tf frame names with and without a leading '/' are the same frame.
std::string Frame(const std::string& name) {
  return !name.empty() && name[0] == '/' ? name.substr(1) : name;
}

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

// The bag's topics and their message types.
class BagTopics {
 public:
  BagTopics(const rosbag::Bag& bag, std::string bag_name)
      : bag_name_(std::move(bag_name)) {
    rosbag::View all(bag);
    for (const rosbag::ConnectionInfo* c : all.getConnections()) {
      types_[c->topic] = c->datatype;
    }
  }
  bool Has(const std::string& topic) const { return types_.count(topic); }
  // Throws unless `topic` exists with one of `types`.
  std::string Require(const std::string& topic,
                      const std::vector<std::string>& types) const {
    const auto it = types_.find(topic);
    if (it == types_.end()) {
      throw InputError(bag_name_ + ": no topic '" + topic +
                       "' in the bag; it has: " + List());
    }
    if (std::find(types.begin(), types.end(), it->second) == types.end()) {
      std::string expected;
      for (const auto& t : types)
        expected += (expected.empty() ? "" : " or ") + t;
      throw InputError(bag_name_ + ": topic '" + topic + "' holds " +
                       it->second + ", expected " + expected);
    }
    return it->second;
  }
  std::string List() const {
    std::string s;
    for (const auto& [topic, type] : types_) {
      s += (s.empty() ? "" : ", ") + topic + " (" + type + ")";
    }
    return s.empty() ? "no topics" : s;
  }

 private:
  std::string bag_name_;
  std::map<std::string, std::string> types_;
};

// ROS camera_info -> Camera; only plumb_bob (or no distortion) maps onto
// monomap's lens model.
Camera CameraFromInfo(const sensor_msgs::CameraInfo& info,
                      const std::string& where) {
  if (info.K[0] <= 0 || info.K[4] <= 0) {
    throw InputError(where, "K",
                     "no calibration (focal length 0: camera not calibrated)");
  }
  if (info.width == 0 || info.height == 0) {
    throw InputError(where, "width/height", "image size is 0");
  }
  if (info.K[1] != 0.0) {
    throw InputError(where, "K", "skew is not supported (K[0][1] != 0)");
  }
  Camera c;
  c.width = static_cast<int>(info.width);
  c.height = static_cast<int>(info.height);
  c.fx = info.K[0];
  c.cx = info.K[2];
  c.fy = info.K[4];
  c.cy = info.K[5];
  const std::string& model = info.distortion_model;
  const bool no_distortion = std::all_of(info.D.begin(), info.D.end(),
                                         [](double d) { return d == 0; });
  if (model == "plumb_bob" || (model.empty() && no_distortion)) {
    if (info.D.size() > 5 || (!info.D.empty() && info.D.size() < 4)) {
      throw InputError(where, "D",
                       "plumb_bob needs 4 or 5 coefficients, got " +
                           std::to_string(info.D.size()));
    }
    for (size_t i = 0; i < info.D.size(); ++i) c.distortion[i] = info.D[i];
  } else if (model == "equidistant") {
    throw InputError(where, "distortion_model",
                     "'equidistant' (fisheye) is not supported: monomap's "
                     "camera model is plumb_bob only");
  } else {
    throw InputError(where, "distortion_model",
                     "'" + model + "' is not supported (use plumb_bob)");
  }
  try {
    c.Check();
  } catch (const OptionsError& e) {
    throw InputError(where, "K", e.what());
  }
  return c;
}

double Stamp(const ros::Time& header_stamp, const rosbag::MessageInstance& m) {
  // An unset header stamp falls back to the time the bag recorded.
  return header_stamp.isZero() ? m.getTime().toSec() : header_stamp.toSec();
}

struct Odometry {
  std::vector<TimedPose> world_from_base;  // sorted, unique stamps
  std::string child_frame;
};

Odometry ReadOdometry(const rosbag::Bag& bag, const BagTopics& topics,
                      const RosbagImportOptions& o, const std::string& name) {
  Odometry odo;
  if (!o.odom_topic.empty()) {
    topics.Require(o.odom_topic, {kOdometry});
    rosbag::View view(bag, rosbag::TopicQuery(o.odom_topic));
    for (const rosbag::MessageInstance& m : view) {
      const auto msg = m.instantiate<nav_msgs::Odometry>();
      if (!msg) continue;
      odo.child_frame = Frame(msg->child_frame_id);
      odo.world_from_base.push_back(
          {Stamp(msg->header.stamp, m), FromPose(msg->pose.pose)});
    }
  } else {
    topics.Require(o.tf_topic, {kTf});
    const size_t colon = o.odom_tf.find(':');
    const std::string parent = Frame(o.odom_tf.substr(0, colon));
    odo.child_frame = Frame(o.odom_tf.substr(colon + 1));
    rosbag::View view(bag, rosbag::TopicQuery(o.tf_topic));
    for (const rosbag::MessageInstance& m : view) {
      const auto msg = m.instantiate<tf2_msgs::TFMessage>();
      if (!msg) continue;
      for (const auto& t : msg->transforms) {
        if (Frame(t.header.frame_id) != parent ||
            Frame(t.child_frame_id) != odo.child_frame) {
          continue;
        }
        odo.world_from_base.push_back(
            {Stamp(t.header.stamp, m), FromTransform(t.transform)});
      }
    }
  }
  auto& poses = odo.world_from_base;
  std::stable_sort(poses.begin(), poses.end(),
                   [](const TimedPose& a, const TimedPose& b) {
                     return a.timestamp < b.timestamp;
                   });
  poses.erase(std::unique(poses.begin(), poses.end(),
                          [](const TimedPose& a, const TimedPose& b) {
                            return a.timestamp == b.timestamp;
                          }),
              poses.end());
  if (poses.size() < 2) {
    throw InputError(
        name + ": " +
        (o.odom_topic.empty()
             ? "topic '" + o.tf_topic + "': no transform " + o.odom_tf +
                   " (fewer than 2)"
             : "topic '" + o.odom_topic + "': fewer than 2 odometry messages"));
  }
  return odo;
}

// base_from_cam by chaining /tf_static transforms from the camera frame up
// to the base frame; nullopt if the chain does not reach the base.
std::optional<Rigid3d> MountFromTfStatic(const rosbag::Bag& bag,
                                         const BagTopics& topics,
                                         const std::string& tf_static_topic,
                                         const std::string& base,
                                         const std::string& camera) {
  if (base == camera) return Rigid3d::Identity();
  if (!topics.Has(tf_static_topic)) return std::nullopt;
  topics.Require(tf_static_topic, {kTf});
  std::map<std::string, std::pair<std::string, Rigid3d>> parent_from_child;
  rosbag::View view(bag, rosbag::TopicQuery(tf_static_topic));
  for (const rosbag::MessageInstance& m : view) {
    const auto msg = m.instantiate<tf2_msgs::TFMessage>();
    if (!msg) continue;
    for (const auto& t : msg->transforms) {
      parent_from_child[Frame(t.child_frame_id)] = {Frame(t.header.frame_id),
                                                    FromTransform(t.transform)};
    }
  }
  Rigid3d frame_from_cam;  // frame = the current end of the chain
  std::string frame = camera;
  for (size_t hops = 0; hops <= parent_from_child.size(); ++hops) {
    const auto it = parent_from_child.find(frame);
    if (it == parent_from_child.end()) return std::nullopt;
    frame_from_cam = it->second.second * frame_from_cam;
    frame = it->second.first;
    if (frame == base) return frame_from_cam;
  }
  return std::nullopt;  // a cycle
}

// An image message decoded: the pixels (for checks) and the file to write.
struct DecodedImage {
  cv::Mat pixels;
  std::string extension;       // ".png" or ".jpg"
  std::vector<uchar> encoded;  // file contents
  std::string encoding;
};

DecodedImage DecodeRaw(const sensor_msgs::Image& msg,
                       const std::string& where) {
  DecodedImage d;
  d.encoding = msg.encoding;
  d.pixels = PixelsOfImageMsg(msg, where);
  d.extension = ".png";
  if (!cv::imencode(".png", d.pixels, d.encoded)) {
    throw OutputError(where + ": PNG encoding failed");
  }
  return d;
}

// Compressed images are kept byte for byte (no second JPEG loss).
DecodedImage DecodeCompressed(const sensor_msgs::CompressedImage& msg,
                              const std::string& where) {
  DecodedImage d;
  d.encoding = "compressed " + msg.format;
  d.pixels = cv::imdecode(msg.data, cv::IMREAD_UNCHANGED);
  if (d.pixels.empty()) {
    throw InputError(
        where, "data",
        "cannot decode the compressed image (format '" + msg.format + "')");
  }
  const bool png = msg.data.size() > 4 && msg.data[0] == 0x89 &&
                   msg.data[1] == 'P' && msg.data[2] == 'N';
  const bool jpeg =
      msg.data.size() > 2 && msg.data[0] == 0xFF && msg.data[1] == 0xD8;
  if (png || jpeg) {
    d.extension = png ? ".png" : ".jpg";
    d.encoded.assign(msg.data.begin(), msg.data.end());
  } else {
    d.extension = ".png";
    cv::imencode(".png", d.pixels, d.encoded);
  }
  return d;
}

void WriteBytes(const fs::path& path, const std::vector<uchar>& bytes) {
  WriteFileAtomic(path, std::string(bytes.begin(), bytes.end()));
}

struct ImportState {
  const RosbagImportOptions& options;
  std::string name;  // the bag's path for messages
  Camera camera;
  Odometry odometry;
  Rigid3d base_from_cam;
  fs::path dir;
  std::vector<ImportedFrame> frames;
  RosbagImportReport report;
};

// One image message: interpolate the odometry, check and write the image.
void ImportImage(const rosbag::MessageInstance& m, ImportState& s) {
  const std::string where = s.name + ": topic '" + s.options.image_topic + "'";
  std::optional<DecodedImage> image;
  double stamp = 0;
  if (const auto raw = m.instantiate<sensor_msgs::Image>()) {
    stamp = Stamp(raw->header.stamp, m);
    image = DecodeRaw(*raw, where);
  } else if (const auto c = m.instantiate<sensor_msgs::CompressedImage>()) {
    stamp = Stamp(c->header.stamp, m);
    image = DecodeCompressed(*c, where);
  } else {
    return;
  }
  ++s.report.images_in_bag;
  s.report.image_encoding = image->encoding;
  if (image->pixels.cols != s.camera.width ||
      image->pixels.rows != s.camera.height) {
    throw InputError(where, "width/height",
                     "image is " + std::to_string(image->pixels.cols) + "x" +
                         std::to_string(image->pixels.rows) +
                         " but camera_info says " +
                         std::to_string(s.camera.width) + "x" +
                         std::to_string(s.camera.height));
  }
  const auto& odo = s.odometry.world_from_base;
  if (stamp < odo.front().timestamp - 1e-9 ||
      stamp > odo.back().timestamp + 1e-9) {
    ++s.report.dropped_outside_odometry;
    return;
  }
  Rigid3d world_from_base;
  if (!InterpolatePose(odo, stamp, s.options.max_odometry_gap,
                       &world_from_base)) {
    ++s.report.dropped_in_gap;
    return;
  }
  char name[32];
  std::snprintf(name, sizeof(name), "rgb/%06zu", s.frames.size());
  ImportedFrame f;
  f.timestamp = stamp;
  f.image = name + image->extension;
  f.odometry_world_from_cam = world_from_base * s.base_from_cam;
  f.odometry_base =
      PlanarPose(world_from_base, s.options.max_planar_tilt_deg * M_PI / 180,
                 s.options.max_planar_height_m);
  WriteBytes(s.dir / f.image, image->encoded);
  s.frames.push_back(f);
}

std::string ImageFrameId(const rosbag::Bag& bag, const std::string& topic) {
  rosbag::View view(bag, rosbag::TopicQuery(topic));
  for (const rosbag::MessageInstance& m : view) {
    if (const auto raw = m.instantiate<sensor_msgs::Image>()) {
      return Frame(raw->header.frame_id);
    }
    if (const auto c = m.instantiate<sensor_msgs::CompressedImage>()) {
      return Frame(c->header.frame_id);
    }
  }
  return "";
}

Camera ReadCameraInfo(const rosbag::Bag& bag, const std::string& topic,
                      const std::string& name) {
  rosbag::View view(bag, rosbag::TopicQuery(topic));
  for (const rosbag::MessageInstance& m : view) {
    if (const auto info = m.instantiate<sensor_msgs::CameraInfo>()) {
      return CameraFromInfo(*info, name + ": topic '" + topic + "'");
    }
  }
  throw InputError(name + ": topic '" + topic + "': no CameraInfo message");
}

void ResolveMount(const rosbag::Bag& bag, const BagTopics& topics,
                  ImportState& s) {
  const RosbagImportOptions& o = s.options;
  if (!o.camera_mount.empty()) {
    s.base_from_cam = ReadCameraMount(o.camera_mount);
    s.report.mount_source = o.camera_mount.string();
    return;
  }
  const std::string base =
      o.base_frame.empty() ? s.odometry.child_frame : Frame(o.base_frame);
  const std::string camera = o.camera_frame.empty()
                                 ? ImageFrameId(bag, o.image_topic)
                                 : Frame(o.camera_frame);
  const auto mount =
      MountFromTfStatic(bag, topics, o.tf_static_topic, base, camera);
  if (!mount) {
    throw InputError(s.name + ": topic '" + o.tf_static_topic +
                     "': no transform from base frame '" + base +
                     "' to camera frame '" + camera +
                     "' (pass --camera-mount FILE, or --base-frame / "
                     "--camera-frame)");
  }
  s.base_from_cam = *mount;
  s.report.mount_source =
      base == camera ? "identity (odometry of the camera "
                       "frame '" +
                           camera + "')"
                     : o.tf_static_topic + " " + base + " -> " + camera;
}

void ImportFromOpenBag(const rosbag::Bag& bag, ImportState& s) {
  const RosbagImportOptions& o = s.options;
  const BagTopics topics(bag, s.name);
  topics.Require(o.image_topic, {kImage, kCompressed});
  topics.Require(o.camera_info_topic, {kCameraInfo});
  s.camera = ReadCameraInfo(bag, o.camera_info_topic, s.name);
  s.odometry = ReadOdometry(bag, topics, o, s.name);
  ResolveMount(bag, topics, s);
  fs::create_directories(s.dir / "rgb");
  rosbag::View images(bag, rosbag::TopicQuery(o.image_topic));
  for (const rosbag::MessageInstance& m : images) ImportImage(m, s);
  // Bags store messages by receive time; the dataset wants stamp order.
  std::stable_sort(s.frames.begin(), s.frames.end(),
                   [](const ImportedFrame& a, const ImportedFrame& b) {
                     return a.timestamp < b.timestamp;
                   });
}

}  // namespace

RosbagImportReport ImportRosbag(const fs::path& bag_path,
                                const fs::path& out_dir,
                                const RosbagImportOptions& options) {
  options.Check();
  if (!fs::is_regular_file(bag_path)) {
    throw InputError(bag_path.string() + ": bag file not found");
  }
  AtomicDirectory out(out_dir, "dataset");
  ImportState s{options, bag_path.string(), {}, {}, {}, out.path(), {}, {}};
  try {
    rosbag::Bag bag;
    bag.open(bag_path.string(), rosbag::bagmode::Read);
    ImportFromOpenBag(bag, s);
  } catch (const rosbag::BagException& e) {
    throw InputError(s.name +
                     ": cannot read the bag (truncated, unindexed "
                     "or not a ROS 1 bag; `rosbag reindex` may repair it): " +
                     e.what());
  } catch (const ros::Exception& e) {
    throw InputError(s.name + ": corrupt message: " + std::string(e.what()));
  }
  const bool planar = std::all_of(
      s.frames.begin(), s.frames.end(),
      [](const ImportedFrame& f) { return f.odometry_base.has_value(); });
  WriteImportedDataset(
      out.path(), s.camera, s.frames,
      planar ? std::optional<Rigid3d>(s.base_from_cam) : std::nullopt,
      bag_path.string());
  out.Commit();
  RosbagImportReport& r = s.report;
  r.frames_written = static_cast<int>(s.frames.size());
  r.odometry_samples = static_cast<int>(s.odometry.world_from_base.size());
  r.odometry_start = s.odometry.world_from_base.front().timestamp;
  r.odometry_end = s.odometry.world_from_base.back().timestamp;
  r.camera = s.camera;
  r.base_from_cam = s.base_from_cam;
  r.planar = planar && !s.frames.empty();
  return r;
}

}  // namespace monomap
