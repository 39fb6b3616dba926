#include "monomap/io/standard_import.h"

#include <unistd.h>

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <sstream>

#include "monomap/io/dataset.h"
#include "monomap/io/trajectory_io.h"
#include "monomap/util/error.h"
#include "monomap/util/file.h"

namespace monomap {
namespace {
namespace fs = std::filesystem;

// Per process (other checkouts may run the same tests at the same time),
// removed when the test program ends.
const fs::path kDir = fs::temp_directory_path() /
                      ("monomap_standard_import_test_" + std::to_string(getpid()));
struct RemoveAtExit {
  ~RemoveAtExit() {
    std::error_code ec;
    fs::remove_all(kDir, ec);
  }
} remove_at_exit;

// A hand-held camera path: moving forward and sideways, turning slowly.
Rigid3d TruePose(double t) {
  const double s = t - 1000.0;
  return Rigid3d(
      YawRotation(0.2 * s) * Eigen::Quaterniond(Eigen::AngleAxisd(
                                 0.05 * std::sin(s), Eigen::Vector3d::UnitX())),
      Eigen::Vector3d(0.3 * s, 0.1 * std::sin(2 * s), 1.5));
}

// A TUM sequence as distributed: ground truth at 100 Hz over [1000, 1004]
// s, images at 30 Hz from 999.8 s (the first 6 before the ground truth).
fs::path WriteTumSequence(int width, bool with_groundtruth) {
  const fs::path dir = kDir / "rgbd_dataset_freiburg1_test";
  fs::remove_all(dir);
  fs::create_directories(dir / "rgb");
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

TumImportOptions ExactOdometry() {
  TumImportOptions o;
  o.preset = "fr1";
  o.simulated.scale_error = 0;
  o.simulated.translation_noise = 0;
  o.simulated.rotation_noise_deg_per_m = 0;
  return o;
}

TEST(TumImport, PresetAndExactOdometryGiveTheGroundTruth) {
  const fs::path tum = WriteTumSequence(640, true);
  const ImportReport r = ImportTum(tum, kDir / "out", ExactOdometry());
  EXPECT_EQ(r.images_listed, 60);
  EXPECT_EQ(r.dropped, 6);  // 999.8 .. 999.9667 s, before the ground truth
  EXPECT_EQ(r.frames_written, 54);
  EXPECT_TRUE(r.odometry_simulated);
  EXPECT_LT(r.final_drift_m, 1e-9);
  const Dataset ds = LoadDataset(kDir / "out");
  ASSERT_EQ(ds.frames.size(), 54u);
  EXPECT_TRUE(ds.has_groundtruth);
  EXPECT_DOUBLE_EQ(ds.camera.fx, 517.306408);
  EXPECT_DOUBLE_EQ(ds.camera.distortion[4], 1.163314);
  const auto gt_in = ReadTumTrajectory(tum / "groundtruth.txt");
  const auto gt_out = ReadTumTrajectory(kDir / "out" / "groundtruth.txt");
  ASSERT_EQ(gt_out.size(), gt_in.size());  // all of it, at its own rate
  EXPECT_LT((gt_out.back().world_from_cam.translation -
             gt_in.back().world_from_cam.translation)
                .norm(),
            1e-9);
  double worst = 0;
  for (const DatasetFrame& f : ds.frames) {
    ASSERT_TRUE(f.groundtruth_world_from_cam.has_value());
    const Rigid3d& a = f.odometry_world_from_cam;
    const Rigid3d& b = *f.groundtruth_world_from_cam;
    worst = std::max(worst, (a.translation - b.translation).norm() +
                                AngleBetween(a.rotation, b.rotation));
  }
  EXPECT_LT(worst, 1e-6);
}

TEST(TumImport, SimulatedOdometryHasTheChosenScaleAndSeededDrift) {
  const fs::path tum = WriteTumSequence(640, true);
  TumImportOptions o = ExactOdometry();
  o.simulated.scale_error = 0.05;
  ImportTum(tum, kDir / "scaled", o);
  const Dataset ds = LoadDataset(kDir / "scaled");
  double odo_length = 0, gt_length = 0;
  for (size_t i = 1; i < ds.frames.size(); ++i) {
    odo_length += (ds.frames[i].odometry_world_from_cam.translation -
                   ds.frames[i - 1].odometry_world_from_cam.translation)
                      .norm();
    gt_length += (ds.frames[i].groundtruth_world_from_cam->translation -
                  ds.frames[i - 1].groundtruth_world_from_cam->translation)
                     .norm();
  }
  // Without rotation noise, each step is the true step scaled by 1.05.
  EXPECT_NEAR(odo_length / gt_length, 1.05, 1e-6);
  EXPECT_GT(gt_length, 0.5);

  o = TumImportOptions();
  o.preset = "fr1";
  o.simulated.seed = 7;
  const double drift_a = ImportTum(tum, kDir / "a", o).final_drift_m;
  const double drift_b = ImportTum(tum, kDir / "b", o).final_drift_m;
  o.simulated.seed = 8;
  const double drift_c = ImportTum(tum, kDir / "c", o).final_drift_m;
  EXPECT_EQ(drift_a, drift_b);
  EXPECT_EQ(ReadFileToString(kDir / "a" / "odometry.txt"),
            ReadFileToString(kDir / "b" / "odometry.txt"));
  EXPECT_NE(drift_a, drift_c);
  EXPECT_GT(drift_a, 0.005);  // 2% scale error alone over ~0.6 m
}

std::string ImportError(const fs::path& tum, const TumImportOptions& o) {
  try {
    ImportTum(tum, kDir / "failed", o);
  } catch (const Error& e) {
    EXPECT_FALSE(fs::exists(kDir / "failed"));
    return e.what();
  }
  return "";
}

TEST(TumImport, ErrorsNameTheFileOrOption) {
  fs::path tum = WriteTumSequence(320, true);
  std::string e = ImportError(tum, ExactOdometry());
  EXPECT_NE(e.find("999.800000.png: image is 320x240 but preset fr1 is for "
                   "640x480"),
            std::string::npos)
      << e;
  TumImportOptions o = ExactOdometry();
  o.preset.clear();
  o.intrinsics = {260, 260, 159.5, 119.5};
  EXPECT_EQ(ImportTum(tum, kDir / "own", o).camera.width, 320);
  o.intrinsics = {260, 260, 159.5};
  e = ImportError(tum, o);
  EXPECT_NE(e.find("tum.intrinsics: expected fx,fy,cx,cy"), std::string::npos)
      << e;
  o.preset = "fr4";
  o.intrinsics.clear();
  e = ImportError(tum, o);
  EXPECT_NE(e.find("'fr4' is not a TUM camera"), std::string::npos) << e;
  tum = WriteTumSequence(640, false);
  e = ImportError(tum, ExactOdometry());
  EXPECT_NE(e.find("groundtruth.txt: not found"), std::string::npos) << e;
}

// An EuRoC ASL sequence: cam0 at 20 Hz over [1.0, 3.0] s, body ground
// truth at 200 Hz over [1.2, 2.9] s, the camera turned and offset from the
// body (T_BS).
Rigid3d BodyFromCam() {
  Eigen::Matrix3d r;
  r << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  return Rigid3d(
      Eigen::Quaterniond(r) * Eigen::Quaterniond(Eigen::AngleAxisd(
                                  0.1, Eigen::Vector3d(1, 1, 0).normalized())),
      Eigen::Vector3d(-0.02, 0.06, 0.01));
}

fs::path WriteEurocSequence(const std::string& distortion_model) {
  const fs::path dir = kDir / "MH_test";
  const fs::path cam = dir / "mav0" / "cam0";
  fs::remove_all(dir);
  fs::create_directories(cam / "data");
  fs::create_directories(dir / "mav0" / "state_groundtruth_estimate0");
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

TEST(EurocImport, CameraGroundTruthIsBodyTimesTbs) {
  const fs::path seq = WriteEurocSequence("radial-tangential");
  EurocImportOptions o;
  o.simulated = ExactOdometry().simulated;
  const ImportReport r = ImportEuroc(seq, kDir / "euroc", o);
  EXPECT_EQ(r.images_listed, 41);
  EXPECT_EQ(r.dropped, 6);  // 1.00-1.15 s and 2.95-3.00 s
  EXPECT_EQ(r.frames_written, 35);
  const Dataset ds = LoadDataset(kDir / "euroc");
  ASSERT_EQ(ds.frames.size(), 35u);
  EXPECT_DOUBLE_EQ(ds.camera.fx, 70.5);
  EXPECT_DOUBLE_EQ(ds.camera.distortion[3], 1.7e-05);
  double worst = 0;
  for (const DatasetFrame& f : ds.frames) {
    // The ground truth at a frame lies on a 200 Hz sample (every 50 ms).
    const Rigid3d expected = TruePose(1000.0 + f.timestamp) * BodyFromCam();
    for (const Rigid3d& pose :
         {f.odometry_world_from_cam, *f.groundtruth_world_from_cam}) {
      worst =
          std::max(worst, (pose.translation - expected.translation).norm() +
                              AngleBetween(pose.rotation, expected.rotation));
    }
  }
  EXPECT_LT(worst, 1e-6);
}

TEST(EurocImport, EquidistantLensIsKept) {
  const fs::path seq = WriteEurocSequence("equidistant");
  ImportEuroc(seq, kDir / "euroc_fisheye", EurocImportOptions());
  const Dataset ds = LoadDataset(kDir / "euroc_fisheye");
  EXPECT_EQ(ds.camera.model, LensModel::kEquidistant);
  EXPECT_DOUBLE_EQ(ds.camera.distortion[3], 1.7e-05);
  EXPECT_EQ(ds.camera.distortion[4], 0.0);
}

TEST(EurocImport, ErrorsNameTheField) {
  const fs::path seq = WriteEurocSequence("fov");
  std::string e;
  try {
    ImportEuroc(seq, kDir / "euroc_failed", EurocImportOptions());
  } catch (const InputError& error) {
    e = error.what();
  }
  EXPECT_NE(e.find("sensor.yaml: field 'distortion_model': 'fov' is not "
                   "supported"),
            std::string::npos)
      << e;
  EXPECT_FALSE(fs::exists(kDir / "euroc_failed"));
  fs::remove(seq / "mav0" / "cam0" / "sensor.yaml");
  e.clear();
  try {
    ImportEuroc(seq, kDir / "euroc_failed", EurocImportOptions());
  } catch (const InputError& error) {
    e = error.what();
  }
  EXPECT_NE(e.find("sensor.yaml"), std::string::npos) << e;
}

// A KITTI odometry sequence: 20 frames at 10 Hz, rectified cameras 0 and 2
// with a 0.54 m baseline (P2 = K [I | t]), poses of camera 0.
fs::path WriteKittiSequence() {
  const fs::path seq = kDir / "dataset" / "sequences" / "07";
  fs::remove_all(kDir / "dataset");
  fs::create_directories(seq / "image_0");
  fs::create_directories(seq / "image_2");
  fs::create_directories(kDir / "dataset" / "poses");
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
  WriteFileAtomic(kDir / "dataset" / "poses" / "07.txt", poses);
  return seq;
}

TEST(KittiImport, PosesOfCameraZeroAndTwo) {
  const fs::path seq = WriteKittiSequence();
  KittiImportOptions o;
  o.simulated = ExactOdometry().simulated;
  for (int camera : {0, 2}) {
    o.camera = camera;
    const ImportReport r = ImportKitti(seq, kDir / "kitti", o);
    EXPECT_EQ(r.frames_written, 20);
    EXPECT_EQ(r.dropped, 0);
    const Dataset ds = LoadDataset(kDir / "kitti");
    ASSERT_EQ(ds.frames.size(), 20u);
    EXPECT_EQ(ds.camera.width, 80);
    EXPECT_DOUBLE_EQ(ds.camera.cx, 40);
    // P2 = K [I | t] with t = K^-1 (4.2, 0.14, 0.003) = (0.06, 0, 0.003)
    // -> camera 2 sits at -t in camera 0.
    const Rigid3d cam0_from_cam(
        Eigen::Quaterniond::Identity(),
        camera == 0 ? Eigen::Vector3d::Zero()
                    : Eigen::Vector3d(-(4.2 - 40 * 0.003) / 70,
                                      -(0.14 - 30 * 0.003) / 70, -0.003));
    double worst = 0;
    for (const DatasetFrame& f : ds.frames) {
      const Rigid3d expected = TruePose(1000.0 + f.timestamp) * cam0_from_cam;
      worst = std::max(
          worst, (f.odometry_world_from_cam.translation - expected.translation)
                         .norm() +
                     AngleBetween(f.odometry_world_from_cam.rotation,
                                  expected.rotation));
    }
    EXPECT_LT(worst, 1e-6) << "camera " << camera;
  }
}

TEST(KittiImport, MismatchedPosesNameTheFiles) {
  const fs::path seq = WriteKittiSequence();
  WriteFileAtomic(seq / "times.txt",
                  ReadFileToString(seq / "times.txt") + "2.000000e+00\n");
  std::string e;
  try {
    ImportKitti(seq, kDir / "kitti_failed", KittiImportOptions());
  } catch (const InputError& error) {
    e = error.what();
  }
  EXPECT_NE(e.find("07.txt: 20 poses but "), std::string::npos) << e;
  EXPECT_NE(e.find("times.txt has 21 times"), std::string::npos) << e;
  EXPECT_FALSE(fs::exists(kDir / "kitti_failed"));
}

TEST(VideoImport, FramesGetTheOdometryAtTheirTime) {
  fs::create_directories(kDir);
  const fs::path video = kDir / "run.avi";
  {
    cv::VideoWriter writer(video.string(),
                           cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10.0,
                           cv::Size(80, 60));
    ASSERT_TRUE(writer.isOpened());
    for (int k = 0; k < 20; ++k) {
      writer.write(cv::Mat(60, 80, CV_8UC3, cv::Scalar(10 * k, 50, 200)));
    }
  }
  Camera c;
  c.width = 80, c.height = 60, c.fx = c.fy = 70, c.cx = 39.5, c.cy = 29.5;
  WriteCameraYaml(kDir / "video_camera.yaml", c, "test");
  std::vector<TimedPose> odometry;  // 20 Hz over [100, 101.5] s
  for (int i = 0; i <= 30; ++i) {
    odometry.push_back({100.0 + 0.05 * i, TruePose(1000.0 + 0.05 * i)});
  }
  WriteTumTrajectory(kDir / "video_odometry.txt", odometry);
  VideoImportOptions o;
  o.camera_yaml = kDir / "video_camera.yaml";
  o.odometry = kDir / "video_odometry.txt";
  o.start_time = 100.0;
  const ImportReport r = ImportVideo(video, kDir / "video", o);
  EXPECT_EQ(r.images_listed, 20);
  EXPECT_EQ(r.dropped, 4);  // 101.6 .. 101.9 s, after the odometry
  EXPECT_FALSE(fs::exists(kDir / "video.frames"));
  const Dataset ds = LoadDataset(kDir / "video");
  ASSERT_EQ(ds.frames.size(), 16u);
  double worst = 0;
  for (size_t i = 0; i < ds.frames.size(); ++i) {
    EXPECT_NEAR(ds.frames[i].timestamp, 100.0 + 0.1 * i, 1e-6);
    const Rigid3d expected = TruePose(1000.0 + 0.1 * i);
    const Rigid3d& pose = ds.frames[i].odometry_world_from_cam;
    worst = std::max(worst, (pose.translation - expected.translation).norm() +
                                AngleBetween(pose.rotation, expected.rotation));
  }
  EXPECT_LT(worst, 1e-6);
  // Colour survives the MJPEG round trip roughly (frame 5: B = 50).
  EXPECT_NEAR(cv::mean(ds.LoadImage(5, true))[0], 50.0, 6.0);

  c.width = 64;
  WriteCameraYaml(kDir / "video_camera.yaml", c, "test");
  std::string e;
  try {
    ImportVideo(video, kDir / "video_failed", o);
  } catch (const InputError& error) {
    e = error.what();
  }
  EXPECT_NE(e.find("run.avi: frame 0 is 80x60 but"), std::string::npos) << e;
  EXPECT_FALSE(fs::exists(kDir / "video_failed"));
}

}  // namespace
}  // namespace monomap
