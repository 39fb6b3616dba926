#include "monomap/io/rosbag2_import.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include "monomap/io/bag_import_test_suite.h"
#include "monomap/io/bag_test_sequence.h"
#include "monomap/io/rosbag2_test_bag.h"
#include "monomap/util/error.h"
#include "monomap/util/file.h"

namespace monomap {
namespace {
namespace fs = std::filesystem;
using namespace bag_test;
using rosbag2_test::CdrWriter;
using rosbag2_test::Ros2BagWriter;

// Per process (other checkouts may run the same tests at the same time),
// removed when the test program ends.
const fs::path kDir =
    fs::temp_directory_path() /
    ("monomap_rosbag2_import_test_" + std::to_string(getpid()));
struct RemoveAtExit {
  ~RemoveAtExit() {
    std::error_code ec;
    fs::remove_all(kDir, ec);
  }
} remove_at_exit;

// The drive of `spec` as a ROS 2 bag directory kDir/name.
fs::path WriteBag(const std::string& name, const BagSpec& spec) {
  const fs::path dir = kDir / name;
  fs::remove_all(dir);
  Ros2BagWriter bag(dir);
  LogDrive(spec, bag);
  bag.Close();
  return dir;
}

// The format for the shared suite (bag_import_test_suite.h).
struct Ros2 {
  static constexpr const char* kName = "ros2";
  static fs::path Write(const fs::path& dir, const std::string& name,
                        const BagSpec& spec) {
    const fs::path path = dir / name;
    Ros2BagWriter bag(path);
    LogDrive(spec, bag);
    bag.Close();
    return path;
  }
  static RosbagImportReport Import(const fs::path& bag, const fs::path& out,
                                   const RosbagImportOptions& o) {
    return ImportRosbag2(bag, out, o);
  }
};
INSTANTIATE_TYPED_TEST_SUITE_P(Ros2, BagImportTest, Ros2);

TEST(Rosbag2Import, ALoneDb3OrTheMetadataFileWorkToo) {
  const fs::path bag = WriteBag("bag", {});
  EXPECT_TRUE(IsRosbag2(bag));
  EXPECT_TRUE(IsRosbag2(bag / "bag_0.db3"));
  EXPECT_FALSE(IsRosbag2(kDir / "nothing.bag"));
  RosbagImportReport r =
      ImportRosbag2(bag / "bag_0.db3", kDir / "dataset", Options({}));
  EXPECT_EQ(r.frames_written, 18);
  r = ImportRosbag2(bag / "metadata.yaml", kDir / "dataset", Options({}));
  EXPECT_EQ(r.frames_written, 18);
}

std::string ImportError(const fs::path& bag, const RosbagImportOptions& o) {
  return bag_test::ImportError(ImportRosbag2, bag, kDir / "kept", o);
}

#define EXPECT_HAS(text, part) \
  EXPECT_NE((text).find(part), std::string::npos) << (text)

TEST(Rosbag2Import, MissingTopicListsTheBagsTopics) {
  const fs::path bag = WriteBag("bag", {});
  RosbagImportOptions o = Options({});
  o.image_topic = "/camera/image";
  EXPECT_HAS(ImportError(bag, o),
             "bag: no topic '/camera/image' in the bag; it has: "
             "/cam/camera_info (sensor_msgs/msg/CameraInfo), "
             "/cam/image_raw (sensor_msgs/msg/Image), "
             "/odom (nav_msgs/msg/Odometry), "
             "/tf_static (tf2_msgs/msg/TFMessage)");
  o = Options({});
  o.odom_topic = "/cam/image_raw";
  EXPECT_HAS(ImportError(bag, o),
             "topic '/cam/image_raw' holds sensor_msgs/msg/Image, expected "
             "nav_msgs/Odometry");
}

TEST(Rosbag2Import, TruncatedOrCorruptDb3IsNamed) {
  const fs::path bag = WriteBag("bag", {});
  const fs::path db3 = bag / "bag_0.db3";
  const std::string bytes = ReadFileToString(db3);
  WriteFileAtomic(db3, bytes.substr(0, bytes.size() / 2));
  EXPECT_HAS(ImportError(bag, Options({})),
             "bag/bag_0.db3: cannot read the ROS 2 bag storage (truncated, "
             "corrupt or not a sqlite3 .db3 file)");
  WriteFileAtomic(db3, "not a database at all, just some text");
  EXPECT_HAS(ImportError(bag, Options({})), "bag/bag_0.db3: cannot read");
  fs::remove(db3);
  EXPECT_HAS(ImportError(bag, Options({})),
             "metadata.yaml: field 'relative_file_paths': " + db3.string() +
                 ": file not found");
  fs::remove(bag / "metadata.yaml");
  EXPECT_HAS(ImportError(bag, Options({})), "metadata.yaml: file not found");
}

TEST(Rosbag2Import, TruncatedMessageNamesTopicAndField) {
  const fs::path dir = kDir / "cut";
  fs::remove_all(dir);
  {
    Ros2BagWriter bag(dir);
    LogDrive(BagSpec{}, bag);
    // One more image whose pixel data was cut off.
    CdrWriter w;
    w.Header(100.3, "camera_optical");
    w << uint32_t(48) << uint32_t(64) << std::string("mono8") << uint8_t(0)
      << uint32_t(64) << uint32_t(64 * 48);
    const std::string data = w.Data() + std::string(100, '\0');
    bag.Write("/cam/image_raw", "sensor_msgs/msg/Image", 100.3, data);
    bag.Close();
  }
  EXPECT_HAS(ImportError(dir, Options({})),
             "cut/bag_0.db3: topic '/cam/image_raw': field 'data': sequence "
             "of 3072 elements but 100 bytes left");
}

// Compressed images get the image file checks: a PNG whose header claims
// 100000 x 100000 is refused before OpenCV allocates it.
TEST(Rosbag2Import, CompressedImageSizeIsCheckedBeforeDecoding) {
  const fs::path dir = kDir / "huge";
  fs::remove_all(dir);
  BagSpec spec;
  spec.encoding = "png";
  {
    Ros2BagWriter bag(dir);
    LogDrive(spec, bag);
    std::vector<uint8_t> png;
    cv::imencode(".png", TestImage(0, CV_8UC3), png);
    for (int i = 0; i < 4; ++i) {
      png[16 + i] = png[20 + i] = static_cast<uint8_t>(100000u >> (24 - 8 * i));
    }
    CdrWriter w;
    w.Header(100.31, "camera_optical");
    w << std::string("png");
    w.Bytes(png);
    bag.Write(ImageTopic(spec), "sensor_msgs/msg/CompressedImage", 100.31,
              w.Data());
    bag.Close();
  }
  EXPECT_HAS(ImportError(dir, Options(spec)),
             "huge: topic '/cam/image_raw/compressed': field 'data' "
             "(compressed, format 'png'): image size 100000x100000 exceeds "
             "the limit");
}

TEST(Rosbag2Import, McapStorageAndNonCdrSerializationAreRefused) {
  const fs::path dir = kDir / "mcap";
  fs::remove_all(dir);
  {
    Ros2BagWriter bag(dir);
    LogDrive(BagSpec{}, bag);
    bag.Close("mcap");
  }
  EXPECT_HAS(ImportError(dir, Options({})),
             "mcap/metadata.yaml: field 'storage_identifier': 'mcap' is not "
             "supported");
  const fs::path json = kDir / "json";
  fs::remove_all(json);
  {
    Ros2BagWriter bag(json);
    LogDrive(BagSpec{}, bag);
    bag.Write("/odom_json", "nav_msgs/msg/Odometry", 100.0, "{}", "json");
    bag.Close();
  }
  RosbagImportOptions o = Options({});
  o.odom_topic = "/odom_json";
  EXPECT_HAS(ImportError(json, o),
             "json/bag_0.db3: topic '/odom_json': field "
             "'serialization_format': 'json' is not supported (cdr)");
}

}  // namespace
}  // namespace monomap
