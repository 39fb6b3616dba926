#include "monomap/io/rosbag_import.h"

#include <unistd.h>

#include <gtest/gtest.h>

#include <fstream>

#include "monomap/io/dataset.h"
#include "monomap/io/rosbag_test_bag.h"
#include "monomap/io/trajectory_io.h"
#include "monomap/util/error.h"
#include "monomap/util/file.h"

namespace monomap {
namespace {
namespace fs = std::filesystem;
using namespace rosbag_test;

// Per process (other checkouts may run the same tests at the same time),
// removed when the test program ends.
const fs::path kDir = fs::temp_directory_path() /
                      ("monomap_rosbag_import_test_" + std::to_string(getpid()));
struct RemoveAtExit {
  ~RemoveAtExit() {
    std::error_code ec;
    fs::remove_all(kDir, ec);
  }
} remove_at_exit;

Camera TestCamera() {
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

// The base drives along a curve: x linear, y quadratic, yaw linear in time.
Rigid3d BaseAt(double t) {
  const double s = t - 100.0;
  return Rigid3d(YawRotation(0.4 * s),
                 Eigen::Vector3d(1.0 + 0.8 * s, 0.3 * s * s, 0.0));
}

// base_link -> camera_link -> camera_optical: 0.2 m forward, 0.5 m up,
// tilted 10 degrees down, optical axes (z forward, x right, y down).
Rigid3d BaseFromCameraLink() {
  return Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(
                     10 * M_PI / 180, Eigen::Vector3d::UnitY())),
                 Eigen::Vector3d(0.2, 0.0, 0.5));
}
Rigid3d CameraLinkFromOptical() {
  Eigen::Matrix3d r;
  r << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  return Rigid3d(Eigen::Quaterniond(r), Eigen::Vector3d(0.01, 0.02, 0.0));
}

// Image k: a gradient whose offset encodes k.
cv::Mat TestImage(int k, int type) {
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

double ImageStamp(int k) { return 99.9 + 0.04 * k; }
constexpr int kImages = 31;  // 99.9 .. 101.1 s at 25 Hz

struct BagSpec {
  std::string encoding = "mono8";  // or rgb8, bgr8, jpeg, png, 16UC1
  bool odom_as_tf = false;
  bool with_tf_static = true;
  std::string distortion_model = "plumb_bob";
  bool calibrated = true;
};

// Odometry at 10 Hz over [100, 101] s with a gap (100.5, 100.8).
std::vector<double> OdometryStamps() {
  std::vector<double> t;
  for (int i = 0; i <= 10; ++i) {
    if (i == 6 || i == 7) continue;
    t.push_back(100.0 + 0.1 * i);
  }
  return t;
}

fs::path WriteBag(const std::string& name, const BagSpec& spec) {
  fs::create_directories(kDir);
  const fs::path path = kDir / name;
  rosbag::Bag bag(path.string(), rosbag::bagmode::Write);
  auto info = CameraInfoMsg(TestCamera(), "camera_optical", 99.9);
  info.distortion_model = spec.distortion_model;
  if (!spec.calibrated) info.K.fill(0.0);
  bag.write("/cam/camera_info", ros::Time(99.9), info);
  if (spec.with_tf_static) {
    bag.write("/tf_static", ros::Time(99.9),
              TfMsg(BaseFromCameraLink(), "base_link", "camera_link", 0.0));
    bag.write(
        "/tf_static", ros::Time(99.9),
        TfMsg(CameraLinkFromOptical(), "camera_link", "camera_optical", 0.0));
  }
  for (double t : OdometryStamps()) {
    if (spec.odom_as_tf) {
      bag.write("/tf", ros::Time(t), TfMsg(BaseAt(t), "odom", "base_link", t));
    } else {
      bag.write("/odom", ros::Time(t),
                OdometryMsg(BaseAt(t), "odom", "base_link", t));
    }
  }
  for (int k = 0; k < kImages; ++k) {
    const double t = ImageStamp(k);
    if (spec.encoding == "jpeg" || spec.encoding == "png") {
      bag.write("/cam/image_raw/compressed", ros::Time(t),
                CompressedMsg(TestImage(k, CV_8UC3),
                              spec.encoding == "png" ? ".png" : ".jpg",
                              "camera_optical", t));
    } else {
      const int type = spec.encoding == "mono8" ? CV_8UC1 : CV_8UC3;
      bag.write(
          "/cam/image_raw", ros::Time(t),
          ImageMsg(TestImage(k, type), spec.encoding, "camera_optical", t));
    }
  }
  bag.close();
  return path;
}

RosbagImportOptions Options(const BagSpec& spec) {
  RosbagImportOptions o;
  o.image_topic = spec.encoding == "jpeg" || spec.encoding == "png"
                      ? "/cam/image_raw/compressed"
                      : "/cam/image_raw";
  o.camera_info_topic = "/cam/camera_info";
  if (spec.odom_as_tf) {
    o.odom_tf = "odom:base_link";
  } else {
    o.odom_topic = "/odom";
  }
  o.max_odometry_gap = 0.25;
  return o;
}

double PoseError(const Rigid3d& a, const Rigid3d& b) {
  return (a.translation - b.translation).norm() +
         AngleBetween(a.rotation, b.rotation);
}

// Imports a bag of `spec` and checks everything the importer promises.
void CheckImport(const BagSpec& spec) {
  const fs::path bag = WriteBag("test.bag", spec);
  const fs::path out = kDir / "dataset";
  const RosbagImportReport r = ImportRosbag(bag, out, Options(spec));
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
  EXPECT_NEAR(ds.camera.fx, 60, 1e-9);
  EXPECT_NEAR(ds.camera.cy, 23.5, 1e-9);
  EXPECT_NEAR(ds.camera.distortion[3], -0.002, 1e-12);
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

TEST(RosbagImport, Mono8WithOdometryTopic) { CheckImport({}); }

TEST(RosbagImport, Rgb8WithTfOdometry) {
  BagSpec spec;
  spec.encoding = "rgb8";
  spec.odom_as_tf = true;
  CheckImport(spec);
}

TEST(RosbagImport, CompressedPngAndJpeg) {
  BagSpec spec;
  spec.encoding = "png";
  CheckImport(spec);
  spec.encoding = "jpeg";
  CheckImport(spec);
}

// Runs an import expected to fail; returns the message and checks that the
// previous output is left as it was.
std::string ImportError(const fs::path& bag, const RosbagImportOptions& o) {
  const fs::path out = kDir / "kept";
  fs::remove_all(out);
  MarkOutputDirectory(out, "dataset");  // a previous import
  WriteFileAtomic(out / "marker", "old");
  std::string message;
  try {
    ImportRosbag(bag, out, o);
  } catch (const InputError& e) {
    message = e.what();
  }
  EXPECT_TRUE(fs::exists(out / "marker")) << "output replaced on error";
  EXPECT_FALSE(fs::exists(out / "rgb.txt"));
  return message;
}

TEST(RosbagImport, MissingTopicListsTheBagsTopics) {
  const fs::path bag = WriteBag("test.bag", {});
  RosbagImportOptions o = Options({});
  o.image_topic = "/camera/image";
  const std::string e = ImportError(bag, o);
  EXPECT_NE(e.find("test.bag: no topic '/camera/image' in the bag; it has: "
                   "/cam/camera_info (sensor_msgs/CameraInfo), "
                   "/cam/image_raw (sensor_msgs/Image), "
                   "/odom (nav_msgs/Odometry), "
                   "/tf_static (tf2_msgs/TFMessage)"),
            std::string::npos)
      << e;
}

TEST(RosbagImport, TruncatedBagIsNamed) {
  const fs::path bag = WriteBag("test.bag", {});
  const std::string bytes = ReadFileToString(bag);
  const fs::path cut = kDir / "cut.bag";
  WriteFileAtomic(cut, bytes.substr(0, bytes.size() / 2));
  const std::string e = ImportError(cut, Options({}));
  EXPECT_NE(e.find("cut.bag: cannot read the bag"), std::string::npos) << e;
}

TEST(RosbagImport, BadEncodingCalibrationAndLensNameTheField) {
  BagSpec spec;
  spec.encoding = "bgra8";
  std::string e = ImportError(WriteBag("enc.bag", spec), Options(spec));
  EXPECT_NE(e.find("enc.bag: topic '/cam/image_raw': field 'encoding': "
                   "'bgra8' is not supported"),
            std::string::npos)
      << e;
  spec = {};
  spec.calibrated = false;
  e = ImportError(WriteBag("uncal.bag", spec), Options(spec));
  EXPECT_NE(e.find("uncal.bag: topic '/cam/camera_info': field 'K': no "
                   "calibration"),
            std::string::npos)
      << e;
  spec = {};
  spec.distortion_model = "rational_polynomial";
  e = ImportError(WriteBag("rational.bag", spec), Options(spec));
  EXPECT_NE(e.find("rational.bag: topic '/cam/camera_info': field "
                   "'distortion_model': 'rational_polynomial' is not "
                   "supported"),
            std::string::npos)
      << e;
}

TEST(RosbagImport, MissingMountIsAnErrorUnlessAFileGivesIt) {
  BagSpec spec;
  spec.with_tf_static = false;
  const fs::path bag = WriteBag("nomount.bag", spec);
  RosbagImportOptions o = Options(spec);
  const std::string e = ImportError(bag, o);
  EXPECT_NE(e.find("topic '/tf_static': no transform from base frame "
                   "'base_link' to camera frame 'camera_optical'"),
            std::string::npos)
      << e;
  const Rigid3d mount = BaseFromCameraLink() * CameraLinkFromOptical();
  WriteCameraMountYaml(kDir / "mount.yaml", mount);
  o.camera_mount = kDir / "mount.yaml";
  const RosbagImportReport r = ImportRosbag(bag, kDir / "dataset", o);
  EXPECT_LT(PoseError(r.base_from_cam, mount), 1e-9);
  EXPECT_EQ(r.frames_written, 18);
}

}  // namespace
}  // namespace monomap
