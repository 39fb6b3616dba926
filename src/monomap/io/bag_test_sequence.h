// Test helper: the drive both bag importers' tests log into a bag (ROS 1
// with rosbag::Bag, ROS 2 with sqlite3 + fastcdr) and the checks of what
// an import of it must give. Message-independent: each test supplies a
// sink that serializes the messages its way.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "monomap/camera/camera.h"
#include "monomap/geometry/rigid3.h"
#include "monomap/io/bag_import.h"
#include "monomap/io/dataset.h"
#include "monomap/util/angles.h"
#include "monomap/util/error.h"
#include "monomap/util/file.h"

namespace monomap::bag_test {

inline Camera TestCamera() {
  Camera c;
  c.width = 64;
  c.height = 48;
  c.fx = 60;
  c.fy = 61;
  c.cx = 31.5;
  c.cy = 23.5;
  c.distortion = {-0.1, 0.02, 0.001, -0.002, 0.0};
  return c;
}

// The same sensor behind a fisheye lens (camera_info "equidistant").
inline Camera TestFisheyeCamera() {
  Camera c = TestCamera();
  c.fx = c.fy = 30;
  c.model = LensModel::kEquidistant;
  c.distortion = {0.02, -0.004, 0.001, -0.0002, 0.0};
  return c;
}

// The base drives along a curve: x linear, y quadratic, yaw linear in time.
inline Rigid3d BaseAt(double t) {
  const double s = t - 100.0;
  return Rigid3d(YawRotation(0.4 * s),
                 Eigen::Vector3d(1.0 + 0.8 * s, 0.3 * s * s, 0.0));
}

// base_link -> camera_link -> camera_optical: 0.2 m forward, 0.5 m up,
// tilted 10 degrees down, optical axes (z forward, x right, y down).
inline Rigid3d BaseFromCameraLink() {
  return Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(
                     DegToRadMulDiv(10), Eigen::Vector3d::UnitY())),
                 Eigen::Vector3d(0.2, 0.0, 0.5));
}
inline Rigid3d CameraLinkFromOptical() {
  Eigen::Matrix3d r;
  r << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  return Rigid3d(Eigen::Quaterniond(r), Eigen::Vector3d(0.01, 0.02, 0.0));
}

// Image k: a gradient whose offset encodes k.
inline cv::Mat TestImage(int k, int type) {
  cv::Mat image(48, 64, type);
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x) {
      const uchar v = static_cast<uchar>((x * 3 + y * 2 + 7 * k) % 256);
      if (type == CV_8UC1) {
        image.at<uchar>(y, x) = v;
      } else {
        image.at<cv::Vec3b>(y, x) = cv::Vec3b(v, uchar(255 - v), uchar(x));
      }
    }
  }
  return image;
}

inline double ImageStamp(int k) { return 99.9 + 0.04 * k; }
constexpr int kImages = 31;  // 99.9 .. 101.1 s at 25 Hz

struct BagSpec {
  std::string encoding = "mono8";  // or rgb8, bgr8, jpeg, png, 16UC1
  bool odom_as_tf = false;
  bool with_tf_static = true;
  bool fisheye = false;          // an equidistant camera_info
  std::string distortion_model;  // overrides the camera's when set
  bool calibrated = true;
};

// Odometry at 10 Hz over [100, 101] s with a gap (100.5, 100.8).
inline std::vector<double> OdometryStamps() {
  std::vector<double> t;
  for (int i = 0; i <= 10; ++i) {
    if (i == 6 || i == 7) continue;
    t.push_back(100.0 + 0.1 * i);
  }
  return t;
}

inline std::string ImageTopic(const BagSpec& spec) {
  return spec.encoding == "jpeg" || spec.encoding == "png"
             ? "/cam/image_raw/compressed"
             : "/cam/image_raw";
}

// Logs the drive of `spec` into `sink`, which has
//   CameraInfo(topic, stamp, camera, distortion_model, calibrated)
//   Tf(topic, recorded, stamp, parent, child, parent_from_child)
//   Odometry(topic, stamp, parent, child, odom_from_base)
//   Image(topic, stamp, frame, bgr_or_grey, encoding)   raw
//   Compressed(topic, stamp, frame, bgr, ".png" or ".jpg")
template <typename Sink>
void LogDrive(const BagSpec& spec, Sink& sink) {
  const Camera camera = spec.fisheye ? TestFisheyeCamera() : TestCamera();
  const std::string model = !spec.distortion_model.empty()
                                ? spec.distortion_model
                                : LensModelName(camera.model);
  sink.CameraInfo("/cam/camera_info", 99.9, camera, model, spec.calibrated);
  if (spec.with_tf_static) {
    // Static transforms carry stamp 0 in many real bags.
    sink.Tf("/tf_static", 99.9, 0.0, "base_link", "camera_link",
            BaseFromCameraLink());
    sink.Tf("/tf_static", 99.9, 0.0, "camera_link", "camera_optical",
            CameraLinkFromOptical());
  }
  for (double t : OdometryStamps()) {
    if (spec.odom_as_tf) {
      sink.Tf("/tf", t, t, "odom", "base_link", BaseAt(t));
    } else {
      sink.Odometry("/odom", t, "odom", "base_link", BaseAt(t));
    }
  }
  for (int k = 0; k < kImages; ++k) {
    const double t = ImageStamp(k);
    if (spec.encoding == "jpeg" || spec.encoding == "png") {
      sink.Compressed(ImageTopic(spec), t, "camera_optical",
                      TestImage(k, CV_8UC3),
                      spec.encoding == "png" ? ".png" : ".jpg");
    } else {
      const int type = spec.encoding == "mono8" ? CV_8UC1 : CV_8UC3;
      sink.Image(ImageTopic(spec), t, "camera_optical", TestImage(k, type),
                 spec.encoding);
    }
  }
}

inline RosbagImportOptions Options(const BagSpec& spec) {
  RosbagImportOptions o;
  o.image_topic = ImageTopic(spec);
  o.camera_info_topic = "/cam/camera_info";
  if (spec.odom_as_tf) {
    o.odom_tf = "odom:base_link";
  } else {
    o.odom_topic = "/odom";
  }
  o.max_odometry_gap = 0.25;
  return o;
}

inline double PoseError(const Rigid3d& a, const Rigid3d& b) {
  return (a.translation - b.translation).norm() +
         AngleBetween(a.rotation, b.rotation);
}

// Everything an import of the drive of `spec` promises: counts, mount,
// intrinsics, poses interpolated to the image stamps, pixels.
inline void CheckImportedDrive(const BagSpec& spec, const RosbagImportReport& r,
                               const std::filesystem::path& out) {
  // 25 images inside [100, 101] s, 6 outside; 7 of the 25 fall in the
  // odometry gap (100.5, 100.8).
  EXPECT_EQ(r.images_in_bag, kImages);
  EXPECT_EQ(r.dropped_outside_odometry, 6);
  EXPECT_EQ(r.dropped_in_gap, 7);
  EXPECT_EQ(r.frames_written, 18);
  EXPECT_EQ(r.odometry_samples, 9);
  EXPECT_TRUE(r.planar);
  const Rigid3d mount = BaseFromCameraLink() * CameraLinkFromOptical();
  EXPECT_LT(PoseError(r.base_from_cam, mount), 1e-9);

  const Dataset ds = LoadDataset(out);  // what every other command reads
  ASSERT_EQ(ds.frames.size(), 18u);
  ASSERT_TRUE(ds.base_from_cam.has_value());
  EXPECT_LT(PoseError(*ds.base_from_cam, mount), 1e-9);
  const Camera camera = spec.fisheye ? TestFisheyeCamera() : TestCamera();
  EXPECT_EQ(ds.camera.model, camera.model);
  EXPECT_NEAR(ds.camera.fx, camera.fx, 1e-9);
  EXPECT_NEAR(ds.camera.cy, camera.cy, 1e-9);
  for (int i = 0; i < 5; ++i) {
    EXPECT_NEAR(ds.camera.distortion[i], camera.distortion[i], 1e-12) << i;
  }
  double max_pose_error = 0, max_yaw_error = 0, max_pixel_error = 0;
  double max_mean_pixel_error = 0;
  for (size_t i = 0; i < ds.frames.size(); ++i) {
    const DatasetFrame& f = ds.frames[i];
    // Expected: linear interpolation between the 10 Hz samples around the
    // stamp (the curve's y is quadratic, so this differs from BaseAt(t)).
    const double t = f.timestamp;
    const double a = 100.0 + 0.1 * std::floor((t - 100.0) / 0.1 + 1e-9);
    const double s = (t - a) / 0.1;
    const Rigid3d base = Interpolate(BaseAt(a), BaseAt(a + 0.1), s);
    max_pose_error = std::max(
        max_pose_error, PoseError(f.odometry_world_from_cam, base * mount));
    ASSERT_TRUE(f.odometry_base.has_value());
    max_yaw_error = std::max(max_yaw_error,
                             std::abs(f.odometry_base->yaw - 0.4 * (t - 100)));
    const int k = static_cast<int>(std::lround((t - 99.9) / 0.04));
    const bool color = spec.encoding != "mono8";
    cv::Mat expected = TestImage(k, color ? CV_8UC3 : CV_8UC1);
    cv::Mat diff;
    cv::absdiff(ds.LoadImage(i, color), expected, diff);
    double worst = 0;
    cv::minMaxLoc(diff.reshape(1), nullptr, &worst);
    max_pixel_error = std::max(max_pixel_error, worst);
    max_mean_pixel_error =
        std::max(max_mean_pixel_error, cv::mean(diff.reshape(1))[0]);
  }
  EXPECT_LT(max_pose_error, 1e-6);
  EXPECT_LT(max_yaw_error, 1e-6);
  if (spec.encoding == "jpeg") {
    // The bag's JPEG bytes are kept, so only that one compression's loss
    // shows (the pattern's wrap-around edges are its worst case).
    EXPECT_LT(max_mean_pixel_error, 8.0);
  } else {
    EXPECT_EQ(max_pixel_error, 0.0);
  }
}

// Runs `import(bag, out, o)` (ImportRosbag or ImportRosbag2), expected to
// fail with InputError over a previous import in `out`; returns the message
// and checks that the previous output is left as it was.
template <typename Import>
std::string ImportError(Import import, const std::filesystem::path& bag,
                        const std::filesystem::path& out,
                        const RosbagImportOptions& o) {
  std::filesystem::remove_all(out);
  MarkOutputDirectory(out, "dataset");  // a previous import
  WriteFileAtomic(out / "marker", "old");
  std::string message;
  try {
    import(bag, out, o);
  } catch (const InputError& e) {
    message = e.what();
  }
  EXPECT_TRUE(std::filesystem::exists(out / "marker"))
      << "output replaced on error";
  EXPECT_FALSE(std::filesystem::exists(out / "rgb.txt"));
  EXPECT_FALSE(message.empty()) << "no InputError";
  return message;
}

// Without /tf_static the import stops naming the frames; a mount file
// gives the mount instead.
template <typename Import>
void CheckMissingMount(Import import, const std::filesystem::path& bag,
                       const std::filesystem::path& dir) {
  BagSpec spec;
  spec.with_tf_static = false;
  RosbagImportOptions o = Options(spec);
  const std::string e = ImportError(import, bag, dir / "kept", o);
  EXPECT_NE(e.find("topic '/tf_static': no transform from base frame "
                   "'base_link' to camera frame 'camera_optical'"),
            std::string::npos)
      << e;
  const Rigid3d mount = BaseFromCameraLink() * CameraLinkFromOptical();
  WriteCameraMountYaml(dir / "mount.yaml", mount);
  o.camera_mount = dir / "mount.yaml";
  const RosbagImportReport r = import(bag, dir / "dataset", o);
  EXPECT_LT(PoseError(r.base_from_cam, mount), 1e-9);
  EXPECT_EQ(r.frames_written, 18);
}

}  // namespace monomap::bag_test
