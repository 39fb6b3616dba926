#include "monomap/io/standard_import.h"

#include <tbb/parallel_for.h>

#include <cmath>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <random>

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

void OdometryFromGroundTruthOptions::Check() const {
  CheckOption(scale_error > -1.0, "tum.simulated.scale_error", "must be > -1");
  CheckOption(translation_noise >= 0, "tum.simulated.translation_noise",
              "must be >= 0");
  CheckOption(rotation_noise_deg_per_m >= 0,
              "tum.simulated.rotation_noise_deg_per_m", "must be >= 0");
}

void TumImportOptions::Check() const {
  CheckOption(preset.empty() != intrinsics.empty(), "tum.intrinsics",
              "give exactly one of a preset (fr1, fr2, fr3) and intrinsics");
  const size_t n = intrinsics.size();
  CheckOption(n == 0 || n == 4 || n == 8 || n == 9, "tum.intrinsics",
              "expected fx,fy,cx,cy[,k1,k2,p1,p2[,k3]]");
  CheckOption(max_pose_gap > 0, "tum.max_pose_gap", "must be > 0");
  simulated.Check();
}

void EurocImportOptions::Check() const {
  CheckOption(!camera.empty(), "euroc.camera", "must be set");
  CheckOption(max_pose_gap > 0, "euroc.max_pose_gap", "must be > 0");
  simulated.Check();
}

void KittiImportOptions::Check() const {
  CheckOption(camera >= 0 && camera <= 3, "kitti.camera", "must be 0 to 3");
  CheckOption(max_pose_gap > 0, "kitti.max_pose_gap", "must be > 0");
  simulated.Check();
}

void VideoImportOptions::Check() const {
  CheckOption(!camera_yaml.empty(), "video.camera_yaml", "must be set");
  CheckOption(!odometry.empty(), "video.odometry", "must be set");
  CheckOption(std::isfinite(start_time), "video.start_time", "must be finite");
  CheckOption(max_pose_gap > 0, "video.max_pose_gap", "must be > 0");
}

Camera TumPresetCamera(const std::string& name) {
  // Published on the TUM RGB-D benchmark's "file formats" page; fr3's
  // images are already undistorted.
  Camera c;
  c.width = 640;
  c.height = 480;
  if (name == "fr1") {
    c.fx = 517.306408, c.fy = 516.469215, c.cx = 318.643040, c.cy = 255.313989;
    c.distortion = {0.262383, -0.953104, -0.005358, 0.002628, 1.163314};
  } else if (name == "fr2") {
    c.fx = 520.908620, c.fy = 521.007327, c.cx = 325.141442, c.cy = 249.701764;
    c.distortion = {0.231222, -0.784899, -0.003257, -0.000105, 0.917205};
  } else if (name == "fr3") {
    c.fx = 535.4, c.fy = 539.2, c.cx = 320.1, c.cy = 247.6;
  } else {
    throw OptionsError("option tum.preset: '" + name +
                       "' is not a TUM camera (fr1, fr2, fr3)");
  }
  return c;
}

namespace {

struct TumImage {
  double timestamp;
  std::string path;  // relative
  int line;
};

std::vector<TumImage> ReadTumRgbList(const fs::path& list) {
  std::vector<TumImage> images;
  for (const TextLine& line : ReadDataLines(list)) {
    const auto tokens = SplitWhitespace(line.text);
    TumImage im{0.0, "", line.number};
    if (tokens.size() != 2 || !ParseDouble(tokens[0], &im.timestamp)) {
      throw InputError(list.string(), line.number,
                       "expected 'timestamp filename'");
    }
    im.path = tokens[1];
    images.push_back(im);
  }
  if (images.empty()) throw InputError(list.string() + ": no images listed");
  return images;
}

Camera CameraFor(const TumImportOptions& o, const fs::path& first_image) {
  // The camera size comes from the first image: read it with the limits.
  const cv::Mat image = ReadImageFile(first_image, cv::IMREAD_UNCHANGED);
  Camera c;
  if (!o.preset.empty()) {
    c = TumPresetCamera(o.preset);
    if (image.cols != c.width || image.rows != c.height) {
      throw InputError(first_image.string() + ": image is " +
                       std::to_string(image.cols) + "x" +
                       std::to_string(image.rows) + " but preset " + o.preset +
                       " is for 640x480");
    }
    return c;
  }
  c.width = image.cols;
  c.height = image.rows;
  c.fx = o.intrinsics[0], c.fy = o.intrinsics[1];
  c.cx = o.intrinsics[2], c.cy = o.intrinsics[3];
  for (size_t i = 4; i < o.intrinsics.size(); ++i) {
    c.distortion[i - 4] = o.intrinsics[i];
  }
  c.Check();
  return c;
}

// odometry_k = odometry_{k-1} * perturbed(gt_{k-1}^-1 gt_k).
std::vector<Rigid3d> SimulateOdometry(const std::vector<Rigid3d>& gt,
                                      const OdometryFromGroundTruthOptions& o) {
  std::mt19937_64 rng(o.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<Rigid3d> odo = {gt.front()};
  for (size_t k = 1; k < gt.size(); ++k) {
    const Rigid3d step = gt[k - 1].Inverse() * gt[k];
    const double length = step.translation.norm();
    Eigen::Vector3d t_noise, r_noise;
    for (int a = 0; a < 3; ++a) t_noise[a] = normal(rng);
    for (int a = 0; a < 3; ++a) r_noise[a] = normal(rng);
    const Eigen::Vector3d t = (1.0 + o.scale_error) * step.translation +
                              o.translation_noise * length * t_noise;
    const Eigen::Quaterniond r =
        QuaternionFromRotationVector(
            DegToRadMulDiv(o.rotation_noise_deg_per_m) * length * r_noise) *
        step.rotation;
    odo.push_back(odo.back() * Rigid3d(r, t));
  }
  return odo;
}

// Hard link (no copy of a large sequence) or, across file systems, a copy.
void LinkOrCopy(const fs::path& from, const fs::path& to) {
  fs::create_directories(to.parent_path());
  std::error_code ec;
  fs::create_hard_link(from, to, ec);
  if (ec) fs::copy_file(from, to, fs::copy_options::overwrite_existing);
}

// What an importer of a standard layout gathered; the rest is shared.
struct PosedImages {
  fs::path root;                       // images are relative to it
  fs::path list;                       // the image list, for errors
  std::vector<TumImage> images;        // path relative to root
  std::vector<TimedPose> trajectory;   // odometry or ground truth
  std::vector<TimedPose> groundtruth;  // may be empty
  std::string out_prefix;              // where images go in the dataset
};

// Frames out of order, or two at one time, mean a corrupt or spliced list.
void CheckTimesIncrease(const PosedImages& in) {
  for (size_t k = 1; k < in.images.size(); ++k) {
    if (in.images[k].timestamp <= in.images[k - 1].timestamp) {
      char text[160];
      std::snprintf(text, sizeof(text),
                    "timestamp %.9f does not increase (previous %.9f)",
                    in.images[k].timestamp, in.images[k - 1].timestamp);
      throw InputError(in.list.string(), in.images[k].line, text);
    }
  }
}

// Every imported image must decode completely and have the camera's size:
// a truncated frame found here fails the import, naming its list line,
// instead of a later build. Decoded in parallel (grey: for JPEG the cheap
// decode); the first bad image in list order is reported.
void CheckImagesDecode(const PosedImages& in,
                       const std::vector<const TumImage*>& used,
                       const Camera& camera) {
  std::vector<std::string> errors(used.size());
  tbb::parallel_for(size_t{0}, used.size(), [&](size_t k) {
    const fs::path path = in.root / used[k]->path;
    try {
      const cv::Mat image = ReadImageFile(path, cv::IMREAD_GRAYSCALE);
      if (image.cols != camera.width || image.rows != camera.height) {
        errors[k] = path.string() + ": image is " +
                    std::to_string(image.cols) + "x" +
                    std::to_string(image.rows) + ", the camera " +
                    std::to_string(camera.width) + "x" +
                    std::to_string(camera.height);
      }
    } catch (const InputError& e) {
      errors[k] = e.what();
    }
  });
  for (size_t k = 0; k < used.size(); ++k) {
    if (!errors[k].empty()) {
      throw InputError(in.list.string(), used[k]->line, errors[k]);
    }
  }
}

// Interpolates a pose for every image (dropping those without one), links
// the images, simulates odometry if `simulate`, and writes the dataset.
ImportReport ImportPosedImages(const PosedImages& in, const Camera& camera,
                               const fs::path& out_dir, bool simulate,
                               const OdometryFromGroundTruthOptions& sim,
                               double max_pose_gap) {
  ImportReport report;
  report.images_listed = static_cast<int>(in.images.size());
  report.odometry_simulated = simulate;
  report.camera = camera;
  CheckTimesIncrease(in);
  AtomicDirectory out(out_dir, "dataset");
  std::vector<ImportedFrame> frames;
  std::vector<Rigid3d> poses;
  std::vector<const TumImage*> used;
  for (const TumImage& im : in.images) {
    Rigid3d pose;
    if (!InterpolatePose(in.trajectory, im.timestamp, max_pose_gap, &pose)) {
      ++report.dropped;
      continue;
    }
    if (!fs::is_regular_file(in.root / im.path)) {
      throw InputError(in.list.string(), im.line,
                       "image '" + im.path + "' not found");
    }
    const std::string name =
        in.out_prefix + fs::path(im.path).filename().string();
    LinkOrCopy(in.root / im.path, out.path() / name);
    frames.push_back({im.timestamp, name, pose, std::nullopt, std::nullopt});
    poses.push_back(pose);
    used.push_back(&im);
  }
  if (frames.empty()) {
    throw InputError(in.list.string() +
                     ": no image lies within the trajectory's time span");
  }
  CheckImagesDecode(in, used, camera);
  if (simulate) {
    const std::vector<Rigid3d> odo = SimulateOdometry(poses, sim);
    for (size_t k = 0; k < frames.size(); ++k) {
      frames[k].odometry_world_from_cam = odo[k];
      if (k > 0) {
        report.path_length_m +=
            (poses[k].translation - poses[k - 1].translation).norm();
      }
    }
    report.final_drift_m =
        (odo.back().translation - poses.back().translation).norm();
  }
  WriteImportedDataset(out.path(), camera, frames, std::nullopt,
                       in.root.string());
  // The ground truth stays at its own rate, for evaluation only.
  if (!in.groundtruth.empty()) {
    WriteTumTrajectory(
        out.path() / "groundtruth.txt", in.groundtruth,
        "ground truth (world_from_cam) from " + in.root.string());
  }
  out.Commit();
  report.frames_written = static_cast<int>(frames.size());
  return report;
}

}  // namespace

ImportReport ImportTum(const fs::path& dir, const fs::path& out_dir,
                       const TumImportOptions& o) {
  o.Check();
  PosedImages in;
  in.root = dir;
  in.list = dir / "rgb.txt";
  in.images = ReadTumRgbList(in.list);
  in.out_prefix = "rgb/";
  const fs::path gt_path = dir / "groundtruth.txt";
  const bool has_gt = fs::exists(gt_path);
  if (o.odometry.empty() && !has_gt) {
    throw InputError(gt_path.string() +
                     ": not found; without it odometry cannot be simulated "
                     "(pass --odometry FILE)");
  }
  if (has_gt) in.groundtruth = ReadTumTrajectory(gt_path);
  in.trajectory =
      o.odometry.empty() ? in.groundtruth : ReadTumTrajectory(o.odometry);
  const Camera camera = CameraFor(o, dir / in.images.front().path);
  return ImportPosedImages(in, camera, out_dir, o.odometry.empty(), o.simulated,
                           o.max_pose_gap);
}

namespace {

// EuRoC CSV: comma-separated fields, '#' header; timestamps in ns.
struct CsvRow {
  int line;
  std::vector<std::string> fields;
};

std::vector<CsvRow> ReadCsv(const fs::path& path, size_t min_fields) {
  std::vector<CsvRow> rows;
  for (const TextLine& line : ReadDataLines(path)) {
    std::string text = line.text;
    for (char& c : text) c = c == ',' ? ' ' : c;
    CsvRow row{line.number, SplitWhitespace(text)};
    if (row.fields.size() < min_fields) {
      throw InputError(path.string(), line.number,
                       "expected at least " + std::to_string(min_fields) +
                           " comma-separated fields, got " +
                           std::to_string(row.fields.size()));
    }
    rows.push_back(std::move(row));
  }
  if (rows.empty()) throw InputError(path.string() + ": no data lines");
  return rows;
}

double NanosecondsToSeconds(const CsvRow& row, const fs::path& path) {
  double ns = 0;
  if (!ParseDouble(row.fields[0], &ns)) {
    throw InputError(path.string(), row.line,
                     "timestamp '" + row.fields[0] + "' is not a number");
  }
  return ns * 1e-9;
}

// cam0/sensor.yaml -> camera and body_from_cam (T_BS).
Camera ReadEurocSensor(const fs::path& path, Rigid3d* body_from_cam) {
  const YAML::Node root = LoadYamlText(ReadFileToString(path), path);
  if (root["camera_model"] &&
      root["camera_model"].as<std::string>("") != "pinhole") {
    throw InputError(path.string(), "camera_model",
                     "'" + root["camera_model"].as<std::string>("") +
                         "' is not supported (pinhole)");
  }
  const std::string model = root["distortion_model"]
                                ? root["distortion_model"].as<std::string>("")
                                : "";
  // Kalibr's names: radial-tangential is plumb_bob without k3, equidistant
  // the Kannala-Brandt fisheye of ROS and OpenCV.
  const bool fisheye = model == "equidistant";
  if (model != "radial-tangential" && model != "radtan" && !fisheye) {
    throw InputError(path.string(), "distortion_model",
                     "'" + model +
                         "' is not supported (radial-tangential or "
                         "equidistant)");
  }
  const auto size = YamlNumbers(path, root["resolution"], "resolution", 2);
  const auto k = YamlNumbers(path, root["intrinsics"], "intrinsics", 4);
  const auto d = YamlNumbers(path, root["distortion_coefficients"],
                             "distortion_coefficients", 4);
  Camera c;
  c.width = static_cast<int>(size[0]);
  c.height = static_cast<int>(size[1]);
  c.fx = k[0], c.fy = k[1], c.cx = k[2], c.cy = k[3];
  for (int i = 0; i < 4; ++i) c.distortion[i] = d[i];
  if (fisheye) c.model = LensModel::kEquidistant;
  try {
    c.Check();
  } catch (const OptionsError& e) {
    throw InputError(path.string(), "intrinsics", e.what());
  }
  if (!root["T_BS"]) throw InputError(path.string(), "T_BS", "missing");
  *body_from_cam = ParseRigidMatrix(path, root["T_BS"], "T_BS");
  return c;
}

// state_groundtruth_estimate0/data.csv: t, p_RS_R xyz, q_RS_R wxyz, ...
std::vector<TimedPose> ReadEurocGroundTruth(const fs::path& path,
                                            const Rigid3d& body_from_cam) {
  std::vector<TimedPose> poses;
  for (const CsvRow& row : ReadCsv(path, 8)) {
    double v[7];
    for (int i = 0; i < 7; ++i) {
      if (!ParseDouble(row.fields[i + 1], &v[i])) {
        throw InputError(path.string(), row.line,
                         "value '" + row.fields[i + 1] + "' is not a number");
      }
    }
    const Eigen::Quaterniond q(v[3], v[4], v[5], v[6]);
    if (std::abs(q.norm() - 1.0) > 1e-2) {
      throw InputError(path.string(), row.line,
                       "quaternion is not unit length (norm " +
                           std::to_string(q.norm()) + ")");
    }
    const Rigid3d world_from_body(q.normalized(),
                                  Eigen::Vector3d(v[0], v[1], v[2]));
    const double t = NanosecondsToSeconds(row, path);
    if (!poses.empty() && t <= poses.back().timestamp) {
      throw InputError(path.string(), row.line, "timestamp does not increase");
    }
    poses.push_back({t, world_from_body * body_from_cam});
  }
  return poses;
}

}  // namespace

ImportReport ImportEuroc(const fs::path& dir, const fs::path& out_dir,
                         const EurocImportOptions& o) {
  o.Check();
  const fs::path mav = fs::is_directory(dir / "mav0") ? dir / "mav0" : dir;
  const fs::path cam = mav / o.camera;
  Rigid3d body_from_cam;
  const Camera camera = ReadEurocSensor(cam / "sensor.yaml", &body_from_cam);
  PosedImages in;
  in.root = cam / "data";
  in.list = cam / "data.csv";
  in.out_prefix = "rgb/";
  for (const CsvRow& row : ReadCsv(in.list, 2)) {
    in.images.push_back(
        {NanosecondsToSeconds(row, in.list), row.fields[1], row.line});
  }
  // sensor.yaml's resolution must be the images' (the dataset keeps it).
  const fs::path first = in.root / in.images.front().path;
  const cv::Mat image = ReadImageFile(first, cv::IMREAD_UNCHANGED);
  if (image.cols != camera.width || image.rows != camera.height) {
    throw InputError((cam / "sensor.yaml").string(), "resolution",
                     std::to_string(camera.width) + "x" +
                         std::to_string(camera.height) + " but " +
                         first.string() + " is " + std::to_string(image.cols) +
                         "x" + std::to_string(image.rows));
  }
  const fs::path gt_path = mav / "state_groundtruth_estimate0" / "data.csv";
  if (fs::exists(gt_path)) {
    in.groundtruth = ReadEurocGroundTruth(gt_path, body_from_cam);
  } else if (o.odometry.empty()) {
    throw InputError(gt_path.string() +
                     ": not found; without it odometry cannot be simulated "
                     "(pass --odometry FILE)");
  }
  in.trajectory =
      o.odometry.empty() ? in.groundtruth : ReadTumTrajectory(o.odometry);
  return ImportPosedImages(in, camera, out_dir, o.odometry.empty(), o.simulated,
                           o.max_pose_gap);
}

namespace {

// The 12 numbers of a KITTI line "[KEY:] m00 m01 ... m23" (3x4 row-major).
Eigen::Matrix<double, 3, 4> KittiMatrix(const TextLine& line,
                                        const fs::path& path, bool keyed) {
  auto tokens = SplitWhitespace(line.text);
  if (keyed && !tokens.empty()) tokens.erase(tokens.begin());
  if (tokens.size() != 12) {
    throw InputError(path.string(), line.number,
                     "expected 12 numbers (3x4 row-major), got " +
                         std::to_string(tokens.size()));
  }
  Eigen::Matrix<double, 3, 4> m;
  for (int i = 0; i < 12; ++i) {
    if (!ParseDouble(tokens[i], &m(i / 4, i % 4))) {
      throw InputError(path.string(), line.number,
                       "value '" + tokens[i] + "' is not a number");
    }
  }
  return m;
}

// calib.txt's PN -> intrinsics and cam0_from_camN (rectified: a pure
// translation).
Camera KittiCamera(const fs::path& path, int n, Rigid3d* cam0_from_cam) {
  const std::string key = "P" + std::to_string(n) + ":";
  for (const TextLine& line : ReadDataLines(path)) {
    if (line.text.rfind(key, 0) != 0) continue;
    const Eigen::Matrix<double, 3, 4> p = KittiMatrix(line, path, true);
    Camera c;
    c.fx = p(0, 0), c.fy = p(1, 1), c.cx = p(0, 2), c.cy = p(1, 2);
    if (c.fx <= 0 || c.fy <= 0) {
      throw InputError(path.string(), line.number, "focal length <= 0");
    }
    // PN = K [I | t]: x_in_camN = x_in_cam0 + t.
    const Eigen::Vector3d t = p.leftCols<3>().inverse() * p.col(3);
    *cam0_from_cam = Rigid3d(Eigen::Quaterniond::Identity(), -t);
    return c;
  }
  throw InputError(path.string(), key.substr(0, key.size() - 1), "missing");
}

// The poses file: one 3x4 world_from_cam0 per time of `in.images`.
std::vector<TimedPose> ReadKittiPoses(const fs::path& path,
                                      const PosedImages& in,
                                      const Rigid3d& cam0_from_cam) {
  const std::vector<TextLine> lines = ReadDataLines(path);
  if (lines.size() != in.images.size()) {
    throw InputError(path.string() + ": " + std::to_string(lines.size()) +
                     " poses but " + in.list.string() + " has " +
                     std::to_string(in.images.size()) + " times");
  }
  std::vector<TimedPose> poses;
  for (size_t i = 0; i < lines.size(); ++i) {
    const auto m = KittiMatrix(lines[i], path, false);
    const Eigen::Matrix3d r = m.leftCols<3>();
    if (!((r.transpose() * r - Eigen::Matrix3d::Identity()).norm() < 1e-3 &&
          r.determinant() > 0)) {
      throw InputError(path.string(), lines[i].number,
                       "the 3x3 part is not a rotation matrix");
    }
    const Rigid3d world_from_cam0(
        Eigen::Quaterniond(Eigen::Matrix3d(m.leftCols<3>())), m.col(3));
    poses.push_back({in.images[i].timestamp, world_from_cam0 * cam0_from_cam});
  }
  return poses;
}

}  // namespace

ImportReport ImportKitti(const fs::path& seq, const fs::path& out_dir,
                         const KittiImportOptions& o) {
  o.Check();
  Rigid3d cam0_from_cam;
  Camera camera = KittiCamera(seq / "calib.txt", o.camera, &cam0_from_cam);
  const fs::path poses_path = !o.poses.empty()
                                  ? o.poses
                                  : seq.parent_path().parent_path() / "poses" /
                                        (seq.filename().string() + ".txt");
  PosedImages in;
  in.root = seq;
  in.list = seq / "times.txt";
  in.out_prefix = "rgb/";
  const std::string folder = "image_" + std::to_string(o.camera) + "/";
  for (const TextLine& line : ReadDataLines(in.list)) {
    double t = 0;
    if (!ParseDouble(line.text, &t)) {
      throw InputError(in.list.string(), line.number,
                       "'" + line.text + "' is not a time in seconds");
    }
    char name[32];
    std::snprintf(name, sizeof(name), "%06zu.png", in.images.size());
    in.images.push_back({t, folder + name, line.number});
  }
  if (fs::exists(poses_path)) {
    in.groundtruth = ReadKittiPoses(poses_path, in, cam0_from_cam);
  } else if (o.odometry.empty()) {
    throw InputError(poses_path.string() +
                     ": not found; without poses odometry cannot be "
                     "simulated (pass --poses FILE or --odometry FILE)");
  }
  in.trajectory =
      o.odometry.empty() ? in.groundtruth : ReadTumTrajectory(o.odometry);
  const cv::Mat first =
      ReadImageFile(seq / in.images.front().path, cv::IMREAD_UNCHANGED);
  camera.width = first.cols;
  camera.height = first.rows;
  return ImportPosedImages(in, camera, out_dir, o.odometry.empty(), o.simulated,
                           o.max_pose_gap);
}

ImportReport ImportVideo(const fs::path& video, const fs::path& out_dir,
                         const VideoImportOptions& o) {
  o.Check();
  const Camera camera = ReadCameraYaml(o.camera_yaml);
  cv::VideoCapture capture(video.string());
  if (!capture.isOpened()) {
    throw InputError(video.string() + ": cannot open the video");
  }
  // The frames go to a scratch directory beside the output (removed on
  // return), from which ImportPosedImages hard-links them.
  fs::path base = out_dir;
  if (!base.has_filename()) base = base.parent_path();  // "DIR/"
  AtomicDirectory frames(base.string() + ".frames", "scratch");
  PosedImages in;
  in.root = frames.path();
  in.list = video;
  in.out_prefix = "rgb/";
  cv::Mat image;
  while (capture.read(image)) {
    const int index = static_cast<int>(in.images.size());
    if (image.cols != camera.width || image.rows != camera.height) {
      throw InputError(
          video.string() + ": frame " + std::to_string(index) + " is " +
          std::to_string(image.cols) + "x" + std::to_string(image.rows) +
          " but " + o.camera_yaml.string() + " says " +
          std::to_string(camera.width) + "x" + std::to_string(camera.height));
    }
    const double t = o.start_time + capture.get(cv::CAP_PROP_POS_MSEC) * 1e-3;
    char name[32];
    std::snprintf(name, sizeof(name), "%06d.png", index);
    if (!cv::imwrite((frames.path() / name).string(), image)) {
      throw OutputError((frames.path() / name).string() + ": cannot write");
    }
    in.images.push_back({t, name, index + 1});
  }
  if (in.images.empty()) {
    throw InputError(video.string() + ": no frame could be decoded");
  }
  in.trajectory = ReadTumTrajectory(o.odometry);
  if (!o.groundtruth.empty()) in.groundtruth = ReadTumTrajectory(o.groundtruth);
  return ImportPosedImages(in, camera, out_dir, false, {}, o.max_pose_gap);
}

}  // namespace monomap
