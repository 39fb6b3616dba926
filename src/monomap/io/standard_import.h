// Imports standard dataset layouts into monomap's (docs/importing.md).
// TUM RGB-D: a sequence as distributed (rgb.txt with its comment
// header, rgb/*.png, groundtruth.txt; no calibration, no odometry) into
// monomap's dataset layout (docs/importing.md). The intrinsics come from
// the user or a named preset; the odometry from a file or, honestly
// labelled, simulated from the ground truth with chosen errors.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "monomap/camera/camera.h"

namespace monomap {

// Errors of odometry simulated from ground truth: each step between two
// frames (in the previous camera frame) is scaled and perturbed, so the
// odometry drifts like wheel or visual odometry would.
struct OdometryFromGroundTruthOptions {
  // Systematic scale error of every step's translation (0.02: 2% too long).
  double scale_error = 0.02;
  // Random translation error per step, standard deviation as a fraction of
  // the step's length (per axis).
  double translation_noise = 0.01;
  // Random rotation error, standard deviation in degrees per metre moved
  // (per axis).
  double rotation_noise_deg_per_m = 1.0;
  // Seed of the random errors.
  uint64_t seed = 1;

  void Check() const;
};

struct TumImportOptions {
  // Named TUM calibration ("fr1", "fr2", "fr3"); empty: use `intrinsics`.
  std::string preset;
  // fx, fy, cx, cy[, k1, k2, p1, p2[, k3]] (pixels; plumb_bob) when no
  // preset is given.
  std::vector<double> intrinsics;
  // A TUM trajectory file of odometry (world_from_cam); empty: simulate
  // odometry from groundtruth.txt with `simulated`.
  std::filesystem::path odometry;
  OdometryFromGroundTruthOptions simulated;
  // Largest gap (s) between the two trajectory samples around an image;
  // images in larger gaps or outside the trajectory are dropped (counted).
  double max_pose_gap = 0.1;

  void Check() const;
};

struct ImportReport {
  int images_listed = 0;
  int frames_written = 0;
  // Images with no pose (outside the trajectory or in a gap).
  int dropped = 0;
  bool odometry_simulated = false;
  // Of the written odometry against ground truth (when it has both).
  double path_length_m = 0.0;
  double final_drift_m = 0.0;
  Camera camera;
};

struct EurocImportOptions {
  // Camera folder under mav0/ ("cam0" or "cam1").
  std::string camera = "cam0";
  // A TUM trajectory of odometry (world_from_cam); empty: simulate it from
  // the ground truth (state_groundtruth_estimate0) with `simulated`.
  std::filesystem::path odometry;
  OdometryFromGroundTruthOptions simulated;
  // As TumImportOptions::max_pose_gap.
  double max_pose_gap = 0.1;

  void Check() const;
};

struct KittiImportOptions {
  // Camera: 0, 1 (grey) or 2, 3 (colour) = image_N and PN in calib.txt.
  int camera = 0;
  // Ground-truth poses of camera 0 (KITTI poses/NN.txt); empty: SEQ/../../
  // poses/NN.txt if it exists.
  std::filesystem::path poses;
  // A TUM trajectory of odometry (world_from_cam); empty: simulate it from
  // the poses with `simulated`.
  std::filesystem::path odometry;
  OdometryFromGroundTruthOptions simulated;
  // As TumImportOptions::max_pose_gap (KITTI runs at 10 Hz).
  double max_pose_gap = 0.2;

  void Check() const;
};

struct VideoImportOptions {
  // camera_info YAML of the video's camera (required).
  std::filesystem::path camera_yaml;
  // TUM trajectory of odometry (world_from_cam), stamped on the same clock
  // as `start_time` (required).
  std::filesystem::path odometry;
  // Optional TUM ground truth, copied for evaluation.
  std::filesystem::path groundtruth;
  // Time (s) of the video's first frame on the odometry's clock; frame i
  // is at start_time + its position in the video.
  double start_time = 0.0;
  // As TumImportOptions::max_pose_gap.
  double max_pose_gap = 0.2;

  void Check() const;
};

// The published calibration of the TUM RGB-D benchmark's cameras (fr1,
// fr2, fr3; 640x480). Throws OptionsError for another name.
Camera TumPresetCamera(const std::string& name);

// Reads the sequence in `tum_dir` and writes the dataset to `out_dir`
// atomically. Images are hard-linked when possible, copied otherwise.
// Throws InputError naming file and line or field; nothing is written then.
ImportReport ImportTum(const std::filesystem::path& tum_dir,
                       const std::filesystem::path& out_dir,
                       const TumImportOptions& options);

// Reads an EuRoC MAV sequence in the ASL layout (DIR/mav0 or DIR itself:
// CAM/data.csv, CAM/data/*.png, CAM/sensor.yaml with intrinsics,
// radial-tangential distortion and T_BS, state_groundtruth_estimate0/
// data.csv of the body) and writes the dataset to `out_dir` atomically;
// the ground truth becomes the camera's (world_from_body * T_BS).
ImportReport ImportEuroc(const std::filesystem::path& dir,
                         const std::filesystem::path& out_dir,
                         const EurocImportOptions& options);

// Reads a KITTI odometry sequence (SEQ/calib.txt, SEQ/times.txt,
// SEQ/image_N/*.png and the poses file, 3x4 row-major world_from_cam0 per
// line) and writes the dataset to `out_dir` atomically. The images are
// rectified: the camera has no distortion; camera N's poses are camera 0's
// moved by the baseline in PN.
ImportReport ImportKitti(const std::filesystem::path& sequence,
                         const std::filesystem::path& out_dir,
                         const KittiImportOptions& options);

// Reads a video file (anything OpenCV's videoio opens), writes its frames
// as PNG with the odometry interpolated at each frame's time, and writes
// the dataset to `out_dir` atomically. Frames without odometry are dropped
// and counted; a frame of another size than camera_yaml says is an error.
ImportReport ImportVideo(const std::filesystem::path& video,
                         const std::filesystem::path& out_dir,
                         const VideoImportOptions& options);

}  // namespace monomap
