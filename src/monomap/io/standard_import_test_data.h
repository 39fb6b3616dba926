// Test helper: small TUM RGB-D, EuRoC (ASL) and KITTI odometry sequences
// in their published layouts, for the importers' tests and the bad-input
// catalogue (tests/bad_import_test.cc).
#pragma once

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "monomap/geometry/rigid3.h"
#include "monomap/io/trajectory_io.h"
#include "monomap/util/file.h"

namespace monomap::standard_test {
// A hand-held camera path: moving forward and sideways, turning slowly.
inline Rigid3d TruePose(double t) {
  const double s = t - 1000.0;
  return Rigid3d(
      YawRotation(0.2 * s) * Eigen::Quaterniond(Eigen::AngleAxisd(
                                 0.05 * std::sin(s), Eigen::Vector3d::UnitX())),
      Eigen::Vector3d(0.3 * s, 0.1 * std::sin(2 * s), 1.5));
}

// A TUM sequence as distributed: ground truth at 100 Hz over [1000, 1004]
// s, images at 30 Hz from 999.8 s (the first 6 before the ground truth).
inline std::filesystem::path WriteTumSequence(const std::filesystem::path& root,
                                              int width,
                                              bool with_groundtruth) {
  const std::filesystem::path dir = root / "rgbd_dataset_freiburg1_test";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir / "rgb");
  std::string rgb =
      "# color images\n# file: 'rgbd_dataset_freiburg1_test.bag'"
      "\n# timestamp filename\n";
  for (int k = 0; k < 60; ++k) {
    char stamp[64];
    std::snprintf(stamp, sizeof(stamp), "%.6f", 999.8 + k / 30.0);
    const std::string name = "rgb/" + std::string(stamp) + ".png";
    cv::Mat image(width * 3 / 4, width, CV_8UC3, cv::Scalar(k, 2 * k, 100));
    cv::imwrite((dir / name).string(), image);
    rgb += std::string(stamp) + " " + name + "\n";
  }
  WriteFileAtomic(dir / "rgb.txt", rgb);
  if (with_groundtruth) {
    std::vector<TimedPose> gt;
    for (int i = 0; i <= 400; ++i) {
      gt.push_back({1000.0 + i / 100.0, TruePose(1000.0 + i / 100.0)});
    }
    WriteTumTrajectory(dir / "groundtruth.txt", gt, "ground truth trajectory");
  }
  return dir;
}

// An EuRoC ASL sequence: cam0 at 20 Hz over [1.0, 3.0] s, body ground
// truth at 200 Hz over [1.2, 2.9] s, the camera turned and offset from the
// body (T_BS).
inline Rigid3d BodyFromCam() {
  Eigen::Matrix3d r;
  r << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  return Rigid3d(
      Eigen::Quaterniond(r) * Eigen::Quaterniond(Eigen::AngleAxisd(
                                  0.1, Eigen::Vector3d(1, 1, 0).normalized())),
      Eigen::Vector3d(-0.02, 0.06, 0.01));
}

inline std::filesystem::path WriteEurocSequence(
    const std::filesystem::path& root, const std::string& distortion_model) {
  const std::filesystem::path dir = root / "MH_test";
  const std::filesystem::path cam = dir / "mav0" / "cam0";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(cam / "data");
  std::filesystem::create_directories(dir / "mav0" /
                                      "state_groundtruth_estimate0");
  std::string csv = "#timestamp [ns],filename\n";
  for (int k = 0; k <= 40; ++k) {
    const long long ns = 1000000000LL + k * 50000000LL;
    const std::string name = std::to_string(ns) + ".png";
    cv::imwrite((cam / "data" / name).string(),
                cv::Mat(60, 80, CV_8UC1, cv::Scalar(3 * k)));
    csv += std::to_string(ns) + "," + name + "\n";
  }
  WriteFileAtomic(cam / "data.csv", csv);
  const Eigen::Matrix4d t = BodyFromCam().ToMatrix4();
  std::ostringstream yaml;
  yaml.precision(17);
  yaml << "%YAML:1.0\nsensor_type: camera\ncomment: test\nT_BS:\n  cols: 4\n"
       << "  rows: 4\n  data: [";
  for (int i = 0; i < 16; ++i) yaml << (i ? ", " : "") << t(i / 4, i % 4);
  yaml << "]\nrate_hz: 20\nresolution: [80, 60]\ncamera_model: pinhole\n"
       << "intrinsics: [70.5, 70.1, 39.2, 29.9] #fu, fv, cu, cv\n"
       << "distortion_model: " << distortion_model << "\n"
       << "distortion_coefficients: [-0.28, 0.07, 0.0002, 1.7e-05]\n";
  WriteFileAtomic(cam / "sensor.yaml", yaml.str());
  std::ostringstream gt;
  gt.precision(17);
  gt << "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], "
        "q_RS_x [], q_RS_y [], q_RS_z [], v_RS_R_x [m s^-1], ...\n";
  for (int i = 240; i <= 580; ++i) {  // 1.2 .. 2.9 s
    const Rigid3d body = TruePose(1000.0 + i * 0.005);
    const auto& q = body.rotation;
    gt << 5000000LL * i << "," << body.translation.x() << ","
       << body.translation.y() << "," << body.translation.z() << "," << q.w()
       << "," << q.x() << "," << q.y() << "," << q.z()
       << ",0,0,0,0,0,0,0,0,0\n";
  }
  WriteFileAtomic(dir / "mav0" / "state_groundtruth_estimate0" / "data.csv",
                  gt.str());
  return dir;
}

// A KITTI odometry sequence: 20 frames at 10 Hz, rectified cameras 0 and 2
// with a 0.54 m baseline (P2 = K [I | t]), poses of camera 0.
inline std::filesystem::path WriteKittiSequence(
    const std::filesystem::path& root) {
  const std::filesystem::path seq = root / "dataset" / "sequences" / "07";
  std::filesystem::remove_all(root / "dataset");
  std::filesystem::create_directories(seq / "image_0");
  std::filesystem::create_directories(seq / "image_2");
  std::filesystem::create_directories(root / "dataset" / "poses");
  WriteFileAtomic(seq / "calib.txt",
                  "P0: 70 0 40 0 0 70 30 0 0 0 1 0\n"
                  "P1: 70 0 40 -37.8 0 70 30 0 0 0 1 0\n"
                  "P2: 70 0 40 4.2 0 70 30 0.14 0 0 1 0.003\n"
                  "P3: 70 0 40 -33.6 0 70 30 0.14 0 0 1 0.003\n"
                  "Tr: 1 0 0 0 0 1 0 0 0 0 1 0\n");
  std::string times, poses;
  for (int k = 0; k < 20; ++k) {
    char line[512];
    std::snprintf(line, sizeof(line), "%e\n", 0.1 * k);
    times += line;
    const Eigen::Matrix4d m = TruePose(1000.0 + 0.1 * k).ToMatrix4();
    std::ostringstream row;
    row.precision(17);
    for (int i = 0; i < 12; ++i) row << (i ? " " : "") << m(i / 4, i % 4);
    poses += row.str() + "\n";
    char name[32];
    std::snprintf(name, sizeof(name), "%06d.png", k);
    for (const char* folder : {"image_0", "image_2"}) {
      cv::imwrite((seq / folder / name).string(),
                  cv::Mat(60, 80, CV_8UC1, cv::Scalar(5 * k)));
    }
  }
  WriteFileAtomic(seq / "times.txt", times);
  WriteFileAtomic(root / "dataset" / "poses" / "07.txt", poses);
  return seq;
}

}  // namespace monomap::standard_test
