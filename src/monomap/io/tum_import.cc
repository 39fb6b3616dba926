#include "monomap/io/tum_import.h"

#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <random>

#include "monomap/io/dataset_writer.h"
#include "monomap/io/trajectory_io.h"
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
    if (!images.empty() && im.timestamp <= images.back().timestamp) {
      throw InputError(list.string(), line.number,
                       "timestamp " + tokens[0] + " does not increase");
    }
    im.path = tokens[1];
    images.push_back(im);
  }
  if (images.empty()) throw InputError(list.string() + ": no images listed");
  return images;
}

Camera CameraFor(const TumImportOptions& o, const fs::path& first_image) {
  const cv::Mat image = cv::imread(first_image.string(), cv::IMREAD_UNCHANGED);
  if (image.empty()) {
    throw InputError(first_image.string() + ": cannot read the image");
  }
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
        QuaternionFromRotationVector(o.rotation_noise_deg_per_m * M_PI / 180 *
                                     length * r_noise) *
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

}  // namespace

TumImportReport ImportTum(const fs::path& dir, const fs::path& out_dir,
                          const TumImportOptions& o) {
  o.Check();
  const std::vector<TumImage> images = ReadTumRgbList(dir / "rgb.txt");
  const fs::path gt_path = dir / "groundtruth.txt";
  const bool has_gt = fs::exists(gt_path);
  if (o.odometry.empty() && !has_gt) {
    throw InputError(gt_path.string() +
                     ": not found; without it odometry cannot be simulated "
                     "(pass --odometry FILE)");
  }
  const std::vector<TimedPose> trajectory =
      ReadTumTrajectory(o.odometry.empty() ? gt_path : o.odometry);
  TumImportReport report;
  report.images_listed = static_cast<int>(images.size());
  report.odometry_simulated = o.odometry.empty();
  report.camera = CameraFor(o, dir / images.front().path);

  AtomicDirectory out(out_dir);
  std::vector<ImportedFrame> frames;
  std::vector<Rigid3d> poses;
  for (const TumImage& im : images) {
    Rigid3d pose;
    if (!InterpolatePose(trajectory, im.timestamp, o.max_pose_gap, &pose)) {
      ++report.dropped;
      continue;
    }
    if (!fs::is_regular_file(dir / im.path)) {
      throw InputError((dir / "rgb.txt").string(), im.line,
                       "image '" + im.path + "' not found");
    }
    LinkOrCopy(dir / im.path, out.path() / im.path);
    frames.push_back({im.timestamp, im.path, pose, std::nullopt, std::nullopt});
    poses.push_back(pose);
  }
  if (frames.empty()) {
    throw InputError((dir / "rgb.txt").string() +
                     ": no image lies within the trajectory's time span");
  }
  if (report.odometry_simulated) {
    const std::vector<Rigid3d> odo = SimulateOdometry(poses, o.simulated);
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
  WriteImportedDataset(out.path(), report.camera, frames, std::nullopt,
                       dir.string());
  // The ground truth stays as published, for evaluation only.
  if (has_gt) fs::copy_file(gt_path, out.path() / "groundtruth.txt");
  out.Commit();
  report.frames_written = static_cast<int>(frames.size());
  return report;
}

}  // namespace monomap
