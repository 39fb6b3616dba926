#include "monomap/io/rosbag_import.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>

#include "monomap/io/bag_test_sequence.h"
#include "monomap/io/dataset.h"
#include "monomap/io/rosbag_test_bag.h"
#include "monomap/io/trajectory_io.h"
#include "monomap/util/error.h"
#include "monomap/util/file.h"

namespace monomap {
namespace {
namespace fs = std::filesystem;
using namespace rosbag_test;
using namespace bag_test;

// Per process (other checkouts may run the same tests at the same time),
// removed when the test program ends.
const fs::path kDir =
    fs::temp_directory_path() /
    ("monomap_rosbag_import_test_" + std::to_string(getpid()));
struct RemoveAtExit {
  ~RemoveAtExit() {
    std::error_code ec;
    fs::remove_all(kDir, ec);
  }
} remove_at_exit;

fs::path WriteBag(const std::string& name, const BagSpec& spec) {
  fs::create_directories(kDir);
  const fs::path path = kDir / name;
  Ros1Sink sink(path);
  LogDrive(spec, sink);
  return path;
}

// Imports a bag of `spec` and checks everything the importer promises.
void CheckImport(const BagSpec& spec) {
  const fs::path bag = WriteBag("test.bag", spec);
  const fs::path out = kDir / "dataset";
  CheckImportedDrive(spec, ImportRosbag(bag, out, Options(spec)), out);
}

TEST(RosbagImport, Mono8WithOdometryTopic) { CheckImport({}); }

TEST(RosbagImport, Rgb8WithTfOdometry) {
  BagSpec spec;
  spec.encoding = "rgb8";
  spec.odom_as_tf = true;
  CheckImport(spec);
}

TEST(RosbagImport, EquidistantCameraInfo) {
  BagSpec spec;
  spec.fisheye = true;
  CheckImport(spec);
}

TEST(RosbagImport, CompressedPngAndJpeg) {
  BagSpec spec;
  spec.encoding = "png";
  CheckImport(spec);
  spec.encoding = "jpeg";
  CheckImport(spec);
}

std::string ImportError(const fs::path& bag, const RosbagImportOptions& o) {
  return bag_test::ImportError(ImportRosbag, bag, kDir / "kept", o);
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
  CheckMissingMount(ImportRosbag, WriteBag("nomount.bag", spec), kDir);
}

}  // namespace
}  // namespace monomap
