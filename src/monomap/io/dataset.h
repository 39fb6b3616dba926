// Datasets in monomap's layout (TUM RGB-D style, see
// docs/dataset-format.md):
//   camera.yaml            ROS camera_info (plumb_bob or equidistant)
//   rgb.txt                "timestamp relative/path.png"
//   odometry.txt           TUM trajectory of world_from_cam from odometry
//     or odometry2d.txt    "timestamp x y yaw" of the robot base
//        + camera_mount.yaml  base_from_cam
//   groundtruth.txt        optional, evaluation only
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "monomap/camera/camera.h"
#include "monomap/geometry/pose2d.h"
#include "monomap/map/map.h"

namespace monomap {

struct DatasetOptions {
  // Largest time gap (s) between the two odometry samples that bracket a
  // frame; frames in a larger gap are refused, not extrapolated.
  double max_odometry_gap = 0.2;
  // Index of the first frame to use (after sorting by timestamp).
  int first_frame = 0;
  // Number of frames to use; -1 means all from first_frame on.
  int num_frames = -1;
  // Load groundtruth.txt if present (for evaluation only).
  bool load_groundtruth = true;
  // Calibration to use instead of DATASET/camera.yaml (empty: that one),
  // e.g. one written by `monomap calibrate`.
  std::filesystem::path camera_yaml;
  // Largest odometry motion (m) between two consecutive samples; a larger
  // jump is a corrupt sample (0: no limit). See odometry_jump_policy.
  double max_odometry_step_m = 2.0;
  // What to do with a sample beyond max_odometry_step_m: refuse the
  // dataset naming its line, or drop it and list it in
  // Dataset::dropped_odometry_lines.
  enum class JumpPolicy { kReject, kDrop };
  JumpPolicy odometry_jump_policy = JumpPolicy::kReject;

  void Check() const;
};

// Plausibility bounds on odometry values (docs/reliability.md): anything
// beyond is refused as corrupt.
inline constexpr double kMaxOdometryTranslationM = 1e4;
inline constexpr double kMaxOdometryYawRad = 1e4;  // unwrapped yaw

struct DatasetFrame {
  double timestamp = 0.0;
  std::filesystem::path image_path;      // absolute
  Rigid3d odometry_world_from_cam;       // from odometry (drifts)
  std::optional<Pose2d> odometry_base;   // only with odometry2d.txt
  std::optional<Rigid3d> groundtruth_world_from_cam;
};

struct Dataset {
  std::filesystem::path root;
  Camera camera;
  std::vector<DatasetFrame> frames;
  // Set when the odometry came from odometry2d.txt + camera_mount.yaml.
  std::optional<Rigid3d> base_from_cam;
  bool has_groundtruth = false;
  // "file:line" of odometry samples dropped as jumps (JumpPolicy::kDrop).
  std::vector<std::string> dropped_odometry_lines;

  // Loads frame i as 8-bit grey (color=false) or BGR. Throws InputError
  // naming the image if it is unreadable or not of the camera's size.
  cv::Mat LoadImage(size_t i, bool color = false) const;
};

// Loads and validates a dataset directory. Throws InputError naming file
// and line (or field) for anything malformed or inconsistent.
Dataset LoadDataset(const std::filesystem::path& root,
                    const DatasetOptions& options = {});

// Reads a ROS camera_info YAML file.
Camera ReadCameraYaml(const std::filesystem::path& path);
// Writes one (atomically).
void WriteCameraYaml(const std::filesystem::path& path, const Camera& camera,
                     const std::string& name);

// camera_mount.yaml: base_from_cam as
//   base_from_cam: {translation: [x, y, z], rotation_xyzw: [qx, qy, qz, qw]}
Rigid3d ReadCameraMountYaml(const std::filesystem::path& path);
void WriteCameraMountYaml(const std::filesystem::path& path,
                          const Rigid3d& base_from_cam);

}  // namespace monomap
