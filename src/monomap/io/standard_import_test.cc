#include "monomap/io/standard_import.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <sstream>

#include "monomap/io/dataset.h"
#include "monomap/io/standard_import_test_data.h"
#include "monomap/io/trajectory_io.h"
#include "monomap/util/error.h"
#include "monomap/util/file.h"

namespace monomap {
namespace {
namespace fs = std::filesystem;
using namespace standard_test;

// Per process (other checkouts may run the same tests at the same time),
// removed when the test program ends.
const fs::path kDir =
    fs::temp_directory_path() /
    ("monomap_standard_import_test_" + std::to_string(getpid()));
struct RemoveAtExit {
  ~RemoveAtExit() {
    std::error_code ec;
    fs::remove_all(kDir, ec);
  }
} remove_at_exit;

TumImportOptions ExactOdometry() {
  TumImportOptions o;
  o.preset = "fr1";
  o.simulated.scale_error = 0;
  o.simulated.translation_noise = 0;
  o.simulated.rotation_noise_deg_per_m = 0;
  return o;
}

TEST(TumImport, PresetAndExactOdometryGiveTheGroundTruth) {
  const fs::path tum = WriteTumSequence(kDir, 640, true);
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
  const fs::path tum = WriteTumSequence(kDir, 640, true);
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
  fs::path tum = WriteTumSequence(kDir, 320, true);
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
  tum = WriteTumSequence(kDir, 640, false);
  e = ImportError(tum, ExactOdometry());
  EXPECT_NE(e.find("groundtruth.txt: not found"), std::string::npos) << e;
}

TEST(EurocImport, CameraGroundTruthIsBodyTimesTbs) {
  const fs::path seq = WriteEurocSequence(kDir, "radial-tangential");
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
  const fs::path seq = WriteEurocSequence(kDir, "equidistant");
  ImportEuroc(seq, kDir / "euroc_fisheye", EurocImportOptions());
  const Dataset ds = LoadDataset(kDir / "euroc_fisheye");
  EXPECT_EQ(ds.camera.model, LensModel::kEquidistant);
  EXPECT_DOUBLE_EQ(ds.camera.distortion[3], 1.7e-05);
  EXPECT_EQ(ds.camera.distortion[4], 0.0);
}

TEST(EurocImport, ErrorsNameTheField) {
  const fs::path seq = WriteEurocSequence(kDir, "fov");
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

TEST(KittiImport, PosesOfCameraZeroAndTwo) {
  const fs::path seq = WriteKittiSequence(kDir);
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
  const fs::path seq = WriteKittiSequence(kDir);
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
