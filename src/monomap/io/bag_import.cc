#include "monomap/io/bag_import.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>

#include "monomap/io/camera_mount.h"
#include "monomap/io/dataset.h"
#include "monomap/io/dataset_writer.h"
#include "monomap/io/image_file.h"
#include "monomap/io/trajectory_io.h"
#include "monomap/util/angles.h"
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

namespace bag {

std::string CanonicalType(const std::string& type) {
  const size_t msg = type.find("/msg/");
  return msg == std::string::npos ? type
                                  : type.substr(0, msg) + type.substr(msg + 4);
}

namespace {

// The lens of camera_info: distortion_model and D.
void SetLens(const CameraInfo& info, const std::string& where, Camera* c) {
  const bool no_distortion = std::all_of(info.d.begin(), info.d.end(),
                                         [](double d) { return d == 0; });
  const std::string model = info.distortion_model.empty() && no_distortion
                                ? "plumb_bob"
                                : info.distortion_model;
  const std::optional<LensModel> lens = LensModelFromName(model);
  if (!lens) {
    throw InputError(
        where, "distortion_model",
        "'" + model + "' is not supported (plumb_bob or equidistant)");
  }
  c->model = *lens;
  // plumb_bob: k1 k2 p1 p2 [k3]; equidistant: k1 k2 k3 k4.
  const size_t n = info.d.size();
  const bool plumb_bob = c->model == LensModel::kPlumbBob;
  if (!(n == 0 || n == 4 || (plumb_bob && n == 5))) {
    throw InputError(where, "D",
                     model + " needs " + (plumb_bob ? "4 or 5" : "4") +
                         " coefficients, got " + std::to_string(n));
  }
  std::copy(info.d.begin(), info.d.end(), c->distortion.begin());
}

}  // namespace

Camera CameraFromInfo(const CameraInfo& info, const std::string& where) {
  if (info.k[0] <= 0 || info.k[4] <= 0) {
    throw InputError(where, "K",
                     "no calibration (focal length 0: camera not calibrated)");
  }
  if (info.width == 0 || info.height == 0) {
    throw InputError(where, "width/height", "image size is 0");
  }
  if (info.k[1] != 0.0) {
    throw InputError(where, "K", "skew is not supported (K[0][1] != 0)");
  }
  Camera c;
  c.width = static_cast<int>(info.width);
  c.height = static_cast<int>(info.height);
  c.fx = info.k[0];
  c.cx = info.k[2];
  c.fy = info.k[4];
  c.cy = info.k[5];
  SetLens(info, where, &c);
  try {
    c.Check();
  } catch (const OptionsError& e) {
    throw InputError(where, "K", e.what());
  }
  return c;
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

// A stamp or length in messages, to the nanosecond without trailing zeros.
std::string FormatStamp(double v) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.9f", v);
  std::string text = buf;
  while (text.size() > 1 && text.back() == '0') text.pop_back();
  if (text.back() == '.') text.pop_back();
  return text;
}

// The bag's topics and their message types.
class BagTopics {
 public:
  explicit BagTopics(const BagMessages& bag)
      : bag_name_(bag.Name()), types_(bag.Topics()) {}
  bool Has(const std::string& topic) const { return types_.count(topic); }
  // Throws unless `topic` exists with one of `types` (ROS 1 spelling).
  void Require(const std::string& topic,
               const std::vector<std::string>& types) const {
    const auto it = types_.find(topic);
    if (it == types_.end()) {
      throw InputError(bag_name_ + ": no topic '" + topic +
                       "' in the bag; it has: " + List());
    }
    if (std::find(types.begin(), types.end(), CanonicalType(it->second)) ==
        types.end()) {
      std::string expected;
      for (const auto& t : types)
        expected += (expected.empty() ? "" : " or ") + t;
      throw InputError(bag_name_ + ": topic '" + topic + "' holds " +
                       it->second + ", expected " + expected);
    }
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

struct Odometry {
  std::vector<TimedPose> world_from_base;  // increasing stamps
  std::string child_frame;
};

// Stamps are non-decreasing (AppendOdometry); a republished stamp keeps
// its first pose.
void DropRepeatedStamps(std::vector<TimedPose>& poses) {
  poses.erase(std::unique(poses.begin(), poses.end(),
                          [](const TimedPose& a, const TimedPose& b) {
                            return a.timestamp == b.timestamp;
                          }),
              poses.end());
}

// Refuses what a corrupt or spliced log gives (docs/reliability.md): a
// stamp earlier than the previous one of the same stream (a clock reset or
// two logs in one), non-finite or implausible poses.
void AppendOdometry(const Transform& t, const std::string& where,
                    std::vector<TimedPose>& poses) {
  const Rigid3d& p = t.parent_from_child;
  const auto n = std::to_string(poses.size() + 1);
  if (!p.translation.allFinite() || !p.rotation.coeffs().allFinite() ||
      p.translation.norm() >= kMaxOdometryTranslationM) {
    throw InputError(where, "pose",
                     "message " + n + " (stamp " + FormatStamp(t.stamp) +
                         "): not finite or beyond " +
                         FormatStamp(kMaxOdometryTranslationM) + " m");
  }
  if (!poses.empty() && t.stamp < poses.back().timestamp) {
    throw InputError(where, "header.stamp",
                     "message " + n + ": stamp " + FormatStamp(t.stamp) +
                         " is earlier than the previous one " +
                         FormatStamp(poses.back().timestamp) +
                         " (stamps must not go backwards)");
  }
  poses.push_back({t.stamp, p});
}

Odometry ReadOdometry(BagMessages& bag, const BagTopics& topics,
                      const RosbagImportOptions& o) {
  Odometry odo;
  if (!o.odom_topic.empty()) {
    topics.Require(o.odom_topic, {kOdometry});
    const std::string where = bag.Name() + ": topic '" + o.odom_topic + "'";
    bag.ForEachOdometry(o.odom_topic, [&](const Transform& t) {
      odo.child_frame = Frame(t.child);
      AppendOdometry(t, where, odo.world_from_base);
      return true;
    });
  } else {
    topics.Require(o.tf_topic, {kTf});
    const size_t colon = o.odom_tf.find(':');
    const std::string parent = Frame(o.odom_tf.substr(0, colon));
    odo.child_frame = Frame(o.odom_tf.substr(colon + 1));
    const std::string where =
        bag.Name() + ": topic '" + o.tf_topic + "' (" + o.odom_tf + ")";
    bag.ForEachTransform(o.tf_topic, [&](const Transform& t) {
      if (Frame(t.parent) == parent && Frame(t.child) == odo.child_frame) {
        AppendOdometry(t, where, odo.world_from_base);
      }
      return true;
    });
  }
  DropRepeatedStamps(odo.world_from_base);
  if (odo.world_from_base.size() < 2) {
    throw InputError(
        bag.Name() + ": " +
        (o.odom_topic.empty()
             ? "topic '" + o.tf_topic + "': no transform " + o.odom_tf +
                   " (fewer than 2)"
             : "topic '" + o.odom_topic + "': fewer than 2 odometry messages"));
  }
  return odo;
}

// base_from_cam by chaining /tf_static transforms from the camera frame up
// to the base frame; nullopt if the chain does not reach the base.
std::optional<Rigid3d> MountFromTfStatic(BagMessages& bag,
                                         const BagTopics& topics,
                                         const std::string& tf_static_topic,
                                         const std::string& base,
                                         const std::string& camera) {
  if (base == camera) return Rigid3d::Identity();
  if (!topics.Has(tf_static_topic)) return std::nullopt;
  topics.Require(tf_static_topic, {kTf});
  std::map<std::string, std::pair<std::string, Rigid3d>> parent_from_child;
  bag.ForEachTransform(tf_static_topic, [&](const Transform& t) {
    parent_from_child[Frame(t.child)] = {Frame(t.parent), t.parent_from_child};
    return true;
  });
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

}  // namespace

cv::Mat RawImagePixels(const std::string& encoding, uint32_t width,
                       uint32_t height, uint32_t step, const uint8_t* data,
                       size_t size, const std::string& where) {
  int type = 0;
  if (encoding == "mono8") {
    type = CV_8UC1;
  } else if (encoding == "bgr8" || encoding == "rgb8") {
    type = CV_8UC3;
  } else {
    throw InputError(where, "encoding",
                     "'" + encoding +
                         "' is not supported (mono8, bgr8, rgb8 or "
                         "sensor_msgs/CompressedImage)");
  }
  const size_t row_bytes = size_t(width) * CV_ELEM_SIZE(type);
  if (width == 0 || height == 0 || step < row_bytes ||
      size < size_t(step) * height) {
    throw InputError(where, "data",
                     "holds " + std::to_string(size) + " bytes, too few for " +
                         std::to_string(width) + "x" + std::to_string(height) +
                         " " + encoding);
  }
  // The message's buffer viewed in place, then copied.
  const cv::Mat view(int(height), int(width), type, const_cast<uint8_t*>(data),
                     step);
  cv::Mat pixels;
  if (encoding == "rgb8") {
    cv::cvtColor(view, pixels, cv::COLOR_RGB2BGR);
  } else {
    pixels = view.clone();
  }
  return pixels;
}

namespace {

// An image message decoded: the pixels (for checks) and the file to write.
struct DecodedImage {
  cv::Mat pixels;
  std::string extension;       // ".png" or ".jpg"
  std::vector<uchar> encoded;  // file contents
  std::string encoding;
};

DecodedImage DecodeRaw(const Image& msg, const std::string& where) {
  DecodedImage d;
  d.encoding = msg.encoding;
  d.pixels = RawImagePixels(msg.encoding, msg.width, msg.height, msg.step,
                            msg.data.data(), msg.data.size(), where);
  d.extension = ".png";
  if (!cv::imencode(".png", d.pixels, d.encoded)) {
    throw OutputError(where + ": PNG encoding failed");
  }
  return d;
}

// Compressed images are kept byte for byte (no second JPEG loss).
DecodedImage DecodeCompressed(const Image& msg, const std::string& where) {
  DecodedImage d;
  d.encoding = "compressed " + msg.encoding;
  // The file reader's checks: whole PNG/JPEG, size limits before decoding.
  d.pixels = DecodeImageBytes(
      msg.data, cv::IMREAD_UNCHANGED,
      where + ": field 'data' (compressed, format '" + msg.encoding + "')");
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

struct ImportState {
  const RosbagImportOptions& options;
  std::string name;  // the bag's path for messages
  Camera camera;
  Odometry odometry;
  Rigid3d base_from_cam;
  fs::path dir;
  std::vector<ImportedFrame> frames;
  RosbagImportReport report;
  double last_image_stamp = 0;  // of the previous image message
};

void CheckImageSize(const cv::Mat& pixels, const Camera& camera,
                    const std::string& where) {
  if (pixels.cols == camera.width && pixels.rows == camera.height) return;
  throw InputError(where, "width/height",
                   "image is " + std::to_string(pixels.cols) + "x" +
                       std::to_string(pixels.rows) + " but camera_info says " +
                       std::to_string(camera.width) + "x" +
                       std::to_string(camera.height));
}

// One image message: interpolate the odometry, check and write the image.
void ImportImage(const Image& msg, ImportState& s) {
  const std::string where = s.name + ": topic '" + s.options.image_topic + "'";
  const DecodedImage image =
      msg.compressed ? DecodeCompressed(msg, where) : DecodeRaw(msg, where);
  ++s.report.images_in_bag;
  s.report.image_encoding = image.encoding;
  CheckImageSize(image.pixels, s.camera, where);
  // Two frames at one instant, or time running back, is a corrupt log.
  if (s.report.images_in_bag > 1 && msg.stamp <= s.last_image_stamp) {
    throw InputError(where, "header.stamp",
                     "image " + std::to_string(s.report.images_in_bag) +
                         ": stamp " + FormatStamp(msg.stamp) +
                         " does not increase (previous " +
                         FormatStamp(s.last_image_stamp) + ")");
  }
  s.last_image_stamp = msg.stamp;
  const auto& odo = s.odometry.world_from_base;
  if (msg.stamp < odo.front().timestamp - 1e-9 ||
      msg.stamp > odo.back().timestamp + 1e-9) {
    ++s.report.dropped_outside_odometry;
    return;
  }
  Rigid3d world_from_base;
  if (!InterpolatePose(odo, msg.stamp, s.options.max_odometry_gap,
                       &world_from_base)) {
    ++s.report.dropped_in_gap;
    return;
  }
  char name[32];
  std::snprintf(name, sizeof(name), "rgb/%06zu", s.frames.size());
  ImportedFrame f;
  f.timestamp = msg.stamp;
  f.image = name + image.extension;
  f.odometry_world_from_cam = world_from_base * s.base_from_cam;
  f.odometry_base =
      PlanarPose(world_from_base, DegToRadMulDiv(s.options.max_planar_tilt_deg),
                 s.options.max_planar_height_m);
  WriteFileAtomic(s.dir / f.image,
                  std::string(image.encoded.begin(), image.encoded.end()));
  s.frames.push_back(f);
}

std::string ImageFrameId(BagMessages& bag, const std::string& topic) {
  std::string frame;
  bag.ForEachImage(topic, [&](const Image& m) {
    frame = Frame(m.frame_id);
    return false;
  });
  return frame;
}

Camera ReadCameraInfo(BagMessages& bag, const std::string& topic) {
  std::optional<Camera> camera;
  const std::string where = bag.Name() + ": topic '" + topic + "'";
  bag.ForEachCameraInfo(topic, [&](const CameraInfo& info) {
    camera = CameraFromInfo(info, where);
    return false;
  });
  if (!camera) throw InputError(where + ": no CameraInfo message");
  return *camera;
}

void ResolveMount(BagMessages& bag, const BagTopics& topics, ImportState& s) {
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
      base == camera
          ? "identity (odometry of the camera frame '" + camera + "')"
          : o.tf_static_topic + " " + base + " -> " + camera;
}

void ReadAll(BagMessages& bag, ImportState& s) {
  const RosbagImportOptions& o = s.options;
  const BagTopics topics(bag);
  topics.Require(o.image_topic, {kImage, kCompressed});
  topics.Require(o.camera_info_topic, {kCameraInfo});
  s.camera = ReadCameraInfo(bag, o.camera_info_topic);
  s.odometry = ReadOdometry(bag, topics, o);
  ResolveMount(bag, topics, s);
  fs::create_directories(s.dir / "rgb");
  bag.ForEachImage(o.image_topic, [&](const Image& m) {
    ImportImage(m, s);
    return true;
  });
  if (s.frames.empty()) {
    throw InputError(
        s.name + ": topic '" + o.image_topic + "': none of its " +
        std::to_string(s.report.images_in_bag) +
        " images lies within the odometry (" +
        FormatStamp(s.odometry.world_from_base.front().timestamp) + " to " +
        FormatStamp(s.odometry.world_from_base.back().timestamp) +
        " s, gaps up to " + FormatStamp(o.max_odometry_gap) + " s)");
  }
}

}  // namespace

RosbagImportReport ImportBag(BagMessages& bag, const fs::path& out_dir,
                             const RosbagImportOptions& options) {
  options.Check();
  AtomicDirectory out(out_dir, "dataset");
  ImportState s{options, bag.Name(), {}, {}, {}, out.path(), {}, {}};
  ReadAll(bag, s);
  const bool planar = std::all_of(
      s.frames.begin(), s.frames.end(),
      [](const ImportedFrame& f) { return f.odometry_base.has_value(); });
  WriteImportedDataset(
      out.path(), s.camera, s.frames,
      planar ? std::optional<Rigid3d>(s.base_from_cam) : std::nullopt, s.name);
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

}  // namespace bag
}  // namespace monomap
