#include "monomap/io/rosbag_import.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>

#include "monomap/io/bag_import_test_suite.h"
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

// The format for the shared suite (bag_import_test_suite.h).
struct Ros1 {
  static constexpr const char* kName = "ros1";
  static fs::path Write(const fs::path& dir, const std::string& name,
                        const BagSpec& spec) {
    const fs::path path = dir / (name + ".bag");
    Ros1Sink sink(path);
    LogDrive(spec, sink);
    return path;
  }
  static RosbagImportReport Import(const fs::path& bag, const fs::path& out,
                                   const RosbagImportOptions& o) {
    return ImportRosbag(bag, out, o);
  }
};
INSTANTIATE_TYPED_TEST_SUITE_P(Ros1, BagImportTest, Ros1);

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

}  // namespace
}  // namespace monomap
