#include "monomap/io/dataset.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "monomap/io/camera_mount.h"
#include "monomap/io/image_file.h"
#include "monomap/io/trajectory_io.h"
#include "monomap/util/error.h"
#include "monomap/util/file.h"

namespace monomap {
namespace fs = std::filesystem;

void DatasetOptions::Check() const {
  CheckOption(max_odometry_gap > 0, "dataset.max_odometry_gap", "must be > 0");
  CheckOption(first_frame >= 0, "dataset.first_frame", "must be >= 0");
  CheckOption(num_frames == -1 || num_frames > 0, "dataset.num_frames",
              "must be -1 (all) or > 0");
  CheckOption(max_odometry_step_m >= 0, "dataset.max_odometry_step_m",
              "must be >= 0 (0: no limit)");
}

namespace {

YAML::Node LoadYaml(const fs::path& path) {
  const std::string text = ReadFileToString(path);
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError(path.string(), e.mark.line + 1,
                     "malformed YAML: " + e.msg);
  }
}

std::vector<double> ReadNumbers(const fs::path& path, const YAML::Node& node,
                                const std::string& field, size_t count) {
  if (!node || !node.IsSequence()) {
    throw InputError(path.string(), field, "missing or not a list");
  }
  if (node.size() != count) {
    throw InputError(path.string(), field,
                     "expected " + std::to_string(count) + " numbers, got " +
                         std::to_string(node.size()));
  }
  std::vector<double> values;
  for (const auto& v : node) {
    double d = 0;
    try {
      d = v.as<double>();
    } catch (const YAML::Exception&) {
      throw InputError(path.string(), field, "value is not a number");
    }
    if (!std::isfinite(d)) {
      throw InputError(path.string(), field, "value is not finite");
    }
    values.push_back(d);
  }
  return values;
}

int ReadInt(const fs::path& path, const YAML::Node& root,
            const std::string& field) {
  const YAML::Node n = root[field];
  if (!n) throw InputError(path.string(), field, "missing");
  try {
    return n.as<int>();
  } catch (const YAML::Exception&) {
    throw InputError(path.string(), field, "not an integer");
  }
}

struct RgbEntry {
  double timestamp;
  fs::path path;
  int line;
};

std::vector<RgbEntry> ReadRgbList(const fs::path& root) {
  const fs::path list = root / "rgb.txt";
  std::vector<RgbEntry> entries;
  for (const TextLine& line : ReadDataLines(list)) {
    const auto tokens = SplitWhitespace(line.text);
    if (tokens.size() != 2) {
      throw InputError(list.string(), line.number,
                       "expected 'timestamp path', got " +
                           std::to_string(tokens.size()) + " fields");
    }
    RgbEntry e;
    if (!ParseDouble(tokens[0], &e.timestamp)) {
      throw InputError(list.string(), line.number,
                       "timestamp '" + tokens[0] + "' is not a number");
    }
    if (!entries.empty() && e.timestamp <= entries.back().timestamp) {
      throw InputError(list.string(), line.number,
                       "timestamp " + tokens[0] + " does not increase");
    }
    e.path = root / tokens[1];
    std::error_code ec;
    if (!fs::is_regular_file(e.path, ec)) {
      throw InputError(
          list.string(), line.number,
          "image '" + tokens[1] + "' not found (or not a regular file)");
    }
    e.line = line.number;
    entries.push_back(e);
  }
  if (entries.empty()) throw InputError(list.string() + ": no frames listed");
  return entries;
}

std::vector<std::pair<double, Pose2d>> ReadOdometry2d(
    const fs::path& path, std::vector<int>* line_numbers) {
  std::vector<std::pair<double, Pose2d>> out;
  for (const TextLine& line : ReadDataLines(path)) {
    const auto tokens = SplitWhitespace(line.text);
    if (tokens.size() != 4) {
      throw InputError(path.string(), line.number,
                       "expected 'timestamp x y yaw', got " +
                           std::to_string(tokens.size()) + " fields");
    }
    double v[4];
    for (int i = 0; i < 4; ++i) {
      if (!ParseDouble(tokens[i], &v[i])) {
        throw InputError(path.string(), line.number,
                         "value '" + tokens[i] + "' is not a finite number");
      }
    }
    if (!out.empty() && v[0] <= out.back().first) {
      throw InputError(path.string(), line.number,
                       "timestamp " + tokens[0] + " does not increase");
    }
    out.push_back({v[0], Pose2d{v[1], v[2], v[3]}});
    line_numbers->push_back(line.number);
  }
  if (out.empty()) throw InputError(path.string() + ": no poses");
  return out;
}

// Refuses odometry values beyond the plausibility bounds, and handles
// jumps larger than options.max_odometry_step_m between consecutive
// samples per options.odometry_jump_policy (dropped samples are removed
// from `samples` and listed in `dropped`). `position` gives a sample's
// position (m), `yaw` its unwrapped yaw (rad; 0 if it has none).
template <typename Sample, typename Position, typename Yaw>
void CheckOdometryPlausible(const fs::path& path, const DatasetOptions& options,
                            Position position, Yaw yaw,
                            std::vector<Sample>* samples,
                            const std::vector<int>& lines,
                            std::vector<std::string>* dropped) {
  std::vector<Sample> kept;
  for (size_t i = 0; i < samples->size(); ++i) {
    const Eigen::Vector3d p = position((*samples)[i]);
    if (!(p.norm() < kMaxOdometryTranslationM)) {
      throw InputError(path.string(), lines[i],
                       "position " + std::to_string(p.norm()) +
                           " m from the origin is beyond the plausible " +
                           std::to_string(kMaxOdometryTranslationM) + " m");
    }
    if (!(std::abs(yaw((*samples)[i])) < kMaxOdometryYawRad)) {
      throw InputError(path.string(), lines[i],
                       "yaw beyond the plausible " +
                           std::to_string(kMaxOdometryYawRad) + " rad");
    }
    const double step = kept.empty() ? 0.0 : (p - position(kept.back())).norm();
    if (options.max_odometry_step_m > 0 && step > options.max_odometry_step_m) {
      const std::string what = "jump of " + std::to_string(step) +
                               " m from the previous sample "
                               "exceeds max_odometry_step_m " +
                               std::to_string(options.max_odometry_step_m);
      if (options.odometry_jump_policy == DatasetOptions::JumpPolicy::kReject) {
        throw InputError(path.string(), lines[i],
                         what + " (--max-odometry-step-m)");
      }
      dropped->push_back(path.string() + ":" + std::to_string(lines[i]));
      continue;
    }
    kept.push_back((*samples)[i]);
  }
  if (kept.size() * 2 < samples->size()) {
    throw InputError(path.string() + ": " +
                     std::to_string(samples->size() - kept.size()) + " of " +
                     std::to_string(samples->size()) +
                     " samples are jumps; the odometry is not usable");
  }
  *samples = std::move(kept);
}

}  // namespace

namespace {

// Runs `read` and turns any yaml-cpp error it lets through (a node of the
// wrong kind, e.g. BadSubscript) into an InputError naming the file.
template <typename Read>
auto WithYamlErrors(const fs::path& path, Read read) {
  try {
    return read();
  } catch (const YAML::Exception& e) {
    throw InputError(path.string(), e.mark.line + 1,
                     "unexpected YAML structure: " + e.msg);
  }
}

Camera ReadCameraYamlNodes(const fs::path& path) {
  const YAML::Node root = LoadYaml(path);
  if (!root.IsMap()) throw InputError(path.string() + ": not a YAML mapping");
  Camera c;
  c.width = ReadInt(path, root, "image_width");
  c.height = ReadInt(path, root, "image_height");
  if (c.width <= 0 || c.height <= 0) {
    throw InputError(path.string(), "image_width/image_height",
                     "must be positive");
  }
  const std::string size_error = ImageSizeLimitError(c.width, c.height);
  if (!size_error.empty()) {
    throw InputError(path.string(), "image_width/image_height", size_error);
  }
  const YAML::Node k = root["camera_matrix"];
  if (!k) throw InputError(path.string(), "camera_matrix", "missing");
  const auto kv = ReadNumbers(path, k["data"], "camera_matrix.data", 9);
  c.fx = kv[0];
  c.cx = kv[2];
  c.fy = kv[4];
  c.cy = kv[5];
  if (c.fx <= 0 || c.fy <= 0) {
    throw InputError(path.string(), "camera_matrix.data",
                     "focal lengths must be positive");
  }
  if (kv[1] != 0.0 || kv[3] != 0.0 || kv[6] != 0.0 || kv[7] != 0.0 ||
      kv[8] != 1.0) {
    throw InputError(path.string(), "camera_matrix.data",
                     "expected [fx 0 cx 0 fy cy 0 0 1] (no skew)");
  }
  if (const YAML::Node model = root["distortion_model"]) {
    const std::string m = model.as<std::string>("");
    if (m != "none" && !m.empty()) {
      const auto lens = LensModelFromName(m);
      if (!lens) {
        throw InputError(
            path.string(), "distortion_model",
            "'" + m + "' is not supported (plumb_bob or equidistant)");
      }
      c.model = *lens;
    }
  }
  const bool fisheye = c.model == LensModel::kEquidistant;
  if (const YAML::Node d = root["distortion_coefficients"]) {
    const YAML::Node data = d["data"];
    if (!data || !data.IsSequence() || data.size() < 4 ||
        data.size() > (fisheye ? 4u : 5u)) {
      throw InputError(path.string(), "distortion_coefficients.data",
                       fisheye ? "expected 4 numbers (equidistant k1 k2 k3 k4)"
                               : "expected 4 or 5 numbers (k1 k2 p1 p2 [k3])");
    }
    const auto dv = ReadNumbers(path, data, "distortion_coefficients.data",
                                data.size());
    for (size_t i = 0; i < dv.size(); ++i) c.distortion[i] = dv[i];
  }
  return c;
}

}  // namespace

Camera ReadCameraYaml(const fs::path& path) {
  return WithYamlErrors(path, [&] { return ReadCameraYamlNodes(path); });
}

void WriteCameraYaml(const fs::path& path, const Camera& c,
                     const std::string& name) {
  std::ostringstream out;
  out.precision(10);
  out << "image_width: " << c.width << "\nimage_height: " << c.height
      << "\ncamera_name: " << name << "\ncamera_matrix:\n  rows: 3\n"
      << "  cols: 3\n  data: [" << c.fx << ", 0.0, " << c.cx << ", 0.0, "
      << c.fy << ", " << c.cy << ", 0.0, 0.0, 1.0]\n"
      << "distortion_model: " << LensModelName(c.model)
      << "\ndistortion_coefficients:\n  rows: 1\n";
  // equidistant: k1 k2 k3 k4; plumb_bob: k1 k2 p1 p2 k3.
  const int n = c.model == LensModel::kEquidistant ? 4 : 5;
  out << "  cols: " << n << "\n  data: [";
  for (int i = 0; i < n; ++i) out << (i ? ", " : "") << c.distortion[i];
  out << "]\n";
  WriteFileAtomic(path, out.str());
}

Rigid3d ReadCameraMountYaml(const fs::path& path) {
  // All accepted forms (matrix, quaternion) live in camera_mount.cc.
  return WithYamlErrors(path, [&] { return ReadCameraMount(path); });
}

void WriteCameraMountYaml(const fs::path& path, const Rigid3d& base_from_cam) {
  std::ostringstream out;
  out.precision(12);
  const auto& t = base_from_cam.translation;
  const auto& q = base_from_cam.rotation;
  out << "# base_from_cam: camera pose in the robot base frame (x forward, "
         "y left, z up, origin on the floor)\n"
      << "base_from_cam:\n  translation: [" << t.x() << ", " << t.y() << ", "
      << t.z() << "]\n  rotation_xyzw: [" << q.x() << ", " << q.y() << ", "
      << q.z() << ", " << q.w() << "]\n";
  WriteFileAtomic(path, out.str());
}

namespace {

// A dataset's odometry: the camera's (6-DoF) and, from odometry2d.txt,
// the base's planar poses.
struct DatasetOdometry {
  std::vector<TimedPose> world_from_cam;
  std::vector<std::pair<double, Pose2d>> planar;
};

// Reads odometry2d.txt (with camera_mount.yaml, into ds->base_from_cam)
// and odometry.txt, dropping implausible samples (counted in ds).
DatasetOdometry ReadDatasetOdometry(const fs::path& root,
                                    const DatasetOptions& options,
                                    Dataset* ds) {
  const fs::path odom_path = root / "odometry.txt";
  const fs::path odom2d_path = root / "odometry2d.txt";
  std::vector<TimedPose> odometry;
  std::vector<std::pair<double, Pose2d>> odometry2d;
  if (PathExists(odom2d_path)) {
    ds->base_from_cam = ReadCameraMountYaml(root / "camera_mount.yaml");
    std::vector<int> lines;
    odometry2d = ReadOdometry2d(odom2d_path, &lines);
    CheckOdometryPlausible(
        odom2d_path, options,
        [](const auto& s) {
          return Eigen::Vector3d(s.second.x, s.second.y, 0.0);
        },
        [](const auto& s) { return s.second.yaw; }, &odometry2d, lines,
        &ds->dropped_odometry_lines);
    for (const auto& [t, p] : odometry2d) {
      odometry.push_back({t, WorldFromCamOfBase(p, *ds->base_from_cam)});
    }
  }
  // odometry.txt, when present, gives the full 6-DoF camera odometry and
  // takes precedence for the 3D pose; odometry2d stays available.
  if (PathExists(odom_path)) {
    std::vector<int> lines;
    odometry = ReadTumTrajectory(odom_path, &lines);
    CheckOdometryPlausible(
        odom_path, options,
        [](const TimedPose& p) { return p.world_from_cam.translation; },
        [](const TimedPose&) { return 0.0; }, &odometry, lines,
        &ds->dropped_odometry_lines);
  } else if (odometry.empty()) {
    throw InputError(root.string() +
                     ": no odometry (need odometry.txt, or odometry2d.txt "
                     "with camera_mount.yaml)");
  }
  return {std::move(odometry), std::move(odometry2d)};
}

// The planar pose at time t, interpolated linearly (yaw unwrapped across
// the pair); none after the last sample, the first sample before it.
std::optional<Pose2d> InterpolatePose2d(
    const std::vector<std::pair<double, Pose2d>>& odometry2d, double t) {
  auto it = std::lower_bound(
      odometry2d.begin(), odometry2d.end(), t - 1e-6,
      [](const auto& p, double time) { return p.first < time; });
  if (it == odometry2d.end()) return std::nullopt;
  if (std::abs(it->first - t) <= 1e-6 || it == odometry2d.begin()) {
    return it->second;
  }
  const auto& a = *std::prev(it);
  const auto& b = *it;
  const double s = (t - a.first) / (b.first - a.first);
  const double dyaw = std::remainder(b.second.yaw - a.second.yaw, 2.0 * M_PI);
  return Pose2d{a.second.x + s * (b.second.x - a.second.x),
                a.second.y + s * (b.second.y - a.second.y),
                a.second.yaw + s * dyaw};
}

// The frame of an rgb.txt entry with its odometry (and ground truth, if
// any) at the image's time. Throws if odometry does not cover it.
DatasetFrame MakeFrame(const fs::path& root, const RgbEntry& rgb,
                       const DatasetOdometry& odometry,
                       const std::vector<TimedPose>* groundtruth,
                       const DatasetOptions& options) {
  DatasetFrame f;
  f.timestamp = rgb.timestamp;
  f.image_path = fs::absolute(rgb.path);
  if (!InterpolatePose(odometry.world_from_cam, f.timestamp,
                       options.max_odometry_gap, &f.odometry_world_from_cam)) {
    throw InputError(
        (root / "rgb.txt").string(), rgb.line,
        "no odometry for frame at t=" + std::to_string(f.timestamp) +
            " (outside the odometry or in a gap larger than " +
            std::to_string(options.max_odometry_gap) + " s)");
  }
  if (!odometry.planar.empty()) {
    f.odometry_base = InterpolatePose2d(odometry.planar, f.timestamp);
  }
  if (groundtruth != nullptr) {
    Rigid3d gt;
    if (InterpolatePose(*groundtruth, f.timestamp, options.max_odometry_gap,
                        &gt)) {
      f.groundtruth_world_from_cam = gt;
    }
  }
  return f;
}

}  // namespace

Dataset LoadDataset(const fs::path& root, const DatasetOptions& options) {
  options.Check();
  std::error_code ec;
  if (!fs::is_directory(root, ec)) {
    throw InputError(root.string() + ": dataset directory not found");
  }
  Dataset ds;
  ds.root = fs::absolute(root);
  ds.camera = ReadCameraYaml(options.camera_yaml.empty() ? root / "camera.yaml"
                                                         : options.camera_yaml);
  const std::vector<RgbEntry> rgb = ReadRgbList(root);
  const DatasetOdometry odometry = ReadDatasetOdometry(root, options, &ds);
  std::vector<TimedPose> groundtruth;
  const fs::path gt_path = root / "groundtruth.txt";
  if (options.load_groundtruth && PathExists(gt_path)) {
    groundtruth = ReadTumTrajectory(gt_path);
    ds.has_groundtruth = true;
  }

  const size_t first = static_cast<size_t>(options.first_frame);
  if (first >= rgb.size()) {
    throw InputError((root / "rgb.txt").string() + ": first_frame " +
                     std::to_string(first) + " but only " +
                     std::to_string(rgb.size()) + " frames listed");
  }
  size_t last = rgb.size();
  if (options.num_frames > 0) {
    last = std::min(last, first + static_cast<size_t>(options.num_frames));
  }
  for (size_t i = first; i < last; ++i) {
    ds.frames.push_back(MakeFrame(root, rgb[i], odometry,
                                  ds.has_groundtruth ? &groundtruth : nullptr,
                                  options));
  }
  return ds;
}

cv::Mat Dataset::LoadImage(size_t i, bool color) const {
  const fs::path& path = frames.at(i).image_path;
  cv::Mat image =
      ReadImageFile(path, color ? cv::IMREAD_COLOR : cv::IMREAD_GRAYSCALE);
  if (image.cols != camera.width || image.rows != camera.height) {
    throw InputError(path.string() + ": image is " +
                     std::to_string(image.cols) + "x" +
                     std::to_string(image.rows) + " but camera.yaml says " +
                     std::to_string(camera.width) + "x" +
                     std::to_string(camera.height));
  }
  return image;
}

}  // namespace monomap
