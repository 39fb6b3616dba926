// The bad-input catalogue of `monomap import` (docs/reliability.md): ROS 1
// bags, ROS 2 bags (sqlite3) and TUM RGB-D, EuRoC and KITTI layouts, each
// corrupted in one way (truncated, wrong topic or message type, missing
// fields, stamps that go backwards, implausible values). Every case must
// give exit 1 with one message naming the file and the topic, field or
// line, and no output (tests/bad_input_catalogue.h). Bags are tested where
// this monomap reads them (MONOMAP_HAVE_ROSBAG, MONOMAP_HAVE_ROSBAG2).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "monomap/io/bag_test_sequence.h"
#include "monomap/io/standard_import_test_data.h"
#include "monomap/util/file.h"
#include "tests/bad_input_catalogue.h"
#ifdef MONOMAP_HAVE_ROSBAG
#include "monomap/io/rosbag_test_bag.h"
#endif
#ifdef MONOMAP_HAVE_ROSBAG2
#include <sqlite3.h>

#include "monomap/io/rosbag2_test_bag.h"
#endif

namespace monomap {
namespace {
namespace fs = std::filesystem;
using bag_test::BagSpec;
using test::Case;

// Per process, removed when the test program ends.
const fs::path kRoot = fs::temp_directory_path() /
                       ("monomap_bad_import_" + std::to_string(getpid()));
struct RemoveAtExit {
  ~RemoveAtExit() {
    std::error_code ec;
    fs::remove_all(kRoot, ec);
  }
} remove_at_exit;

void Append(const fs::path& file, const std::string& text) {
  WriteFileAtomic(file, ReadFileToString(file) + text);
}

// Replaces the first occurrence of `from` in `file` by `to`.
void Replace(const fs::path& file, const std::string& from,
             const std::string& to) {
  std::string text = ReadFileToString(file);
  const size_t at = text.find(from);
  ASSERT_NE(at, std::string::npos) << file << " has no '" << from << "'";
  text.replace(at, from.size(), to);
  WriteFileAtomic(file, text);
}

void CutInHalf(const fs::path& file) {
  const std::string bytes = ReadFileToString(file);
  WriteFileAtomic(file, bytes.substr(0, bytes.size() / 2));
}

// A PNG header that claims `side` x `side`.
void ClaimPngSize(const fs::path& file, uint32_t side) {
  std::string png = ReadFileToString(file);
  for (int i = 0; i < 4; ++i) {
    png[16 + i] = png[20 + i] = static_cast<char>(side >> (24 - 8 * i));
  }
  WriteFileAtomic(file, png);
}

// ---------------------------------------------------------------- bags

// What a case does to the drive that bag_test::LogDrive logs.
struct Tamper {
  bool camera_info_without_size = false;  // width and height left 0
  double odometry_x_offset = 0;           // added to the 5th odometry x
  bool odometry_back_in_time = false;  // 5th /tf odometry stamped 0.35 s early
  bool repeated_image_stamp = false;   // the 10th image has the 9th's stamp
  double image_delay = 0;              // added to every image stamp
  bool short_image = false;            // the 5th image lacks a row
};

// A LogDrive sink that applies a Tamper and passes everything on.
template <typename Sink>
class TamperedSink {
 public:
  TamperedSink(Sink& sink, const Tamper& t) : sink_(sink), t_(t) {}
  void CameraInfo(const std::string& topic, double t, Camera c,
                  const std::string& model, bool calibrated) {
    if (t_.camera_info_without_size) c.width = c.height = 0;
    sink_.CameraInfo(topic, t, c, model, calibrated);
  }
  void Tf(const std::string& topic, double recorded, double stamp,
          const std::string& parent, const std::string& child,
          const Rigid3d& parent_from_child) {
    // Only the header stamp moves: the bag keeps its recording order.
    if (topic == "/tf" && ++tf_ == 5 && t_.odometry_back_in_time) {
      stamp -= 0.35;
    }
    sink_.Tf(topic, recorded, stamp, parent, child, parent_from_child);
  }
  void Odometry(const std::string& topic, double t, const std::string& parent,
                const std::string& child, Rigid3d odom_from_base) {
    if (++odometry_ == 5)
      odom_from_base.translation.x() += t_.odometry_x_offset;
    sink_.Odometry(topic, t, parent, child, odom_from_base);
  }
  void Image(const std::string& topic, double t, const std::string& frame,
             const cv::Mat& image, const std::string& encoding) {
    ++images_;
    const bool cut = t_.short_image && images_ == 5;
    sink_.Image(topic, Stamp(t), frame,
                cut ? image.rowRange(0, image.rows - 1) : image, encoding);
  }
  void Compressed(const std::string& topic, double t, const std::string& frame,
                  const cv::Mat& image, const std::string& ext) {
    ++images_;
    sink_.Compressed(topic, Stamp(t), frame, image, ext);
  }

 private:
  double Stamp(double t) const {
    if (t_.repeated_image_stamp && images_ == 10) t = bag_test::ImageStamp(8);
    return t + t_.image_delay;
  }
  Sink& sink_;
  Tamper t_;
  int tf_ = 0, odometry_ = 0, images_ = 0;
};

// Logs the drive of `spec`, tampered with, to a bag at `path`.
using BagWriter = std::function<void(const fs::path& path, const BagSpec& spec,
                                     const Tamper& t)>;

const char kTopics[] =
    "--image-topic /cam/image_raw --camera-info-topic /cam/camera_info";
const std::string kOdomTopic = std::string(kTopics) + " --odom-topic /odom";
const std::string kOdomTf = std::string(kTopics) + " --odom-tf odom:base_link";

// The cases both bag formats share; `file` is how messages name the bag
// (INPUT is its path), `storage` how the message decoder names it.
std::vector<Case> BagCases(const BagWriter& write, const std::string& file,
                           const std::string& storage) {
  const auto keep = [](const fs::path&) {};
  const auto tampered = [write](const Tamper& t, const BagSpec& spec) {
    return [write, t, spec](const fs::path& p) { write(p, spec, t); };
  };
  BagSpec tf_odometry;
  tf_odometry.odom_as_tf = true;
  Tamper no_size, nan_x, huge_x, back, repeated, late, short_image;
  no_size.camera_info_without_size = true;
  nan_x.odometry_x_offset = std::numeric_limits<double>::quiet_NaN();
  huge_x.odometry_x_offset = 1e300;
  back.odometry_back_in_time = true;
  repeated.repeated_image_stamp = true;
  late.image_delay = 100;
  short_image.short_image = true;
  return {
      {"wrong_image_topic", keep, file + ": no topic '/camera/image'",
       "--image-topic /camera/image --camera-info-topic /cam/camera_info "
       "--odom-topic /odom"},
      {"wrong_odometry_topic", keep, file + ": no topic '/odometry'",
       std::string(kTopics) + " --odom-topic /odometry"},
      {"odometry_topic_of_wrong_type", keep,
       file + ": topic '/cam/camera_info' holds sensor_msgs/",
       std::string(kTopics) + " --odom-topic /cam/camera_info"},
      {"image_topic_of_wrong_type", keep,
       file + ": topic '/odom' holds nav_msgs/",
       "--image-topic /odom --camera-info-topic /cam/camera_info --odom-topic "
       "/odom"},
      {"camera_info_without_size", tampered(no_size, {}),
       file + ": topic '/cam/camera_info': field 'width/height'", kOdomTopic},
      {"odometry_nan", tampered(nan_x, {}),
       storage + ": topic '/odom': field 'pose", kOdomTopic},
      {"odometry_huge", tampered(huge_x, {}),
       file + ": topic '/odom': field 'pose': message 5 (stamp 100.4): not "
              "finite or beyond 10000 m",
       kOdomTopic},
      {"odometry_stamp_back_in_time", tampered(back, tf_odometry),
       file + ": topic '/tf' (odom:base_link): field 'header.stamp'", kOdomTf},
      {"image_stamp_repeated", tampered(repeated, {}),
       file + ": topic '/cam/image_raw': field 'header.stamp'", kOdomTopic},
      {"images_outside_odometry", tampered(late, {}),
       file + ": topic '/cam/image_raw': none of its 31 images", kOdomTopic},
      {"image_short", tampered(short_image, {}),
       file + ": topic '/cam/image_raw': field 'width/height'", kOdomTopic},
  };
}

#ifdef MONOMAP_HAVE_ROSBAG
void WriteRos1Bag(const fs::path& path, const BagSpec& spec, const Tamper& t) {
  fs::remove_all(path);
  fs::create_directories(path.parent_path());
  rosbag_test::Ros1Sink sink(path);
  TamperedSink<rosbag_test::Ros1Sink> tampered(sink, t);
  bag_test::LogDrive(spec, tampered);
}

TEST(BadImport, Ros1Bags) {
  WriteRos1Bag(kRoot / "good.bag", {}, {});
  std::vector<Case> cases = BagCases(WriteRos1Bag, "INPUT", "INPUT");
  cases.push_back(
      {"truncated", CutInHalf, "INPUT: cannot read the bag", kOdomTopic});
  cases.push_back({"empty", [](const fs::path& p) { WriteFileAtomic(p, ""); },
                   "INPUT: cannot read the bag", kOdomTopic});
  test::RunCatalogue(kRoot, "good.bag", "import rosbag INPUT -o OUT -q ARGS",
                     cases);
}
#endif

#ifdef MONOMAP_HAVE_ROSBAG2
void WriteRos2Bag(const fs::path& dir, const BagSpec& spec, const Tamper& t) {
  fs::remove_all(dir);
  rosbag2_test::Ros2BagWriter bag(dir);
  TamperedSink<rosbag2_test::Ros2BagWriter> tampered(bag, t);
  bag_test::LogDrive(spec, tampered);
  bag.Close();
}

// Cuts every message of `topic` to its first `bytes` bytes (fields lost).
void CutMessages(const fs::path& db3, const std::string& topic, int bytes) {
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(db3.c_str(), &db), SQLITE_OK);
  const std::string sql =
      "UPDATE messages SET data = substr(data, 1, " + std::to_string(bytes) +
      ") WHERE topic_id = (SELECT id FROM topics WHERE name = '" + topic + "')";
  EXPECT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, nullptr),
            SQLITE_OK);
  sqlite3_close(db);
}

TEST(BadImport, Ros2Bags) {
  WriteRos2Bag(kRoot / "good_ros2", {}, {});
  std::vector<Case> cases = BagCases(WriteRos2Bag, "INPUT", "INPUT/bag_0.db3");
  cases.push_back({"truncated_db3",
                   [](const fs::path& p) { CutInHalf(p / "bag_0.db3"); },
                   "INPUT/bag_0.db3: cannot read", kOdomTopic});
  cases.push_back({"camera_info_fields_missing",
                   [](const fs::path& p) {
                     CutMessages(p / "bag_0.db3", "/cam/camera_info", 40);
                   },
                   "INPUT/bag_0.db3: topic '/cam/camera_info': field '",
                   kOdomTopic});
  cases.push_back(
      {"odometry_fields_missing",
       [](const fs::path& p) { CutMessages(p / "bag_0.db3", "/odom", 60); },
       "INPUT/bag_0.db3: topic '/odom': field '", kOdomTopic});
  cases.push_back({"metadata_storage_mcap",
                   [](const fs::path& p) {
                     Replace(p / "metadata.yaml", "storage_identifier: sqlite3",
                             "storage_identifier: mcap");
                   },
                   "INPUT/metadata.yaml: field 'storage_identifier'",
                   kOdomTopic});
  cases.push_back({"metadata_not_yaml",
                   [](const fs::path& p) {
                     WriteFileAtomic(p / "metadata.yaml", "a: [b\n");
                   },
                   "INPUT/metadata.yaml:", kOdomTopic});
  test::RunCatalogue(kRoot, "good_ros2", "import rosbag INPUT -o OUT -q ARGS",
                     cases);
}
#endif

// ------------------------------------------------------ standard layouts

TEST(BadImport, TumSequences) {
  const fs::path good = standard_test::WriteTumSequence(kRoot, 640, true);
  const std::string first = "rgb/999.800000.png";
  const std::vector<Case> cases = {
      {"rgb_list_backwards",
       [](const fs::path& d) { Append(d / "rgb.txt", "999.0 rgb/x.png\n"); },
       "INPUT/rgb.txt:64: timestamp 999.000000000 does not increase"},
      {"rgb_list_malformed",
       [](const fs::path& d) { Append(d / "rgb.txt", "1001.5\n"); },
       "INPUT/rgb.txt:64: expected 'timestamp filename'"},
      {"groundtruth_backwards",
       [](const fs::path& d) {
         Append(d / "groundtruth.txt", "999.0 0 0 0 0 0 0 1\n");
       },
       "INPUT/groundtruth.txt:404: timestamp 999.0 does not increase"},
      {"groundtruth_truncated_line",
       [](const fs::path& d) { Append(d / "groundtruth.txt", "1004.5 1 2\n"); },
       "INPUT/groundtruth.txt:404: expected 8 values"},
      {"groundtruth_nan",
       [](const fs::path& d) {
         Append(d / "groundtruth.txt", "1004.5 nan 0 0 0 0 0 1\n");
       },
       "INPUT/groundtruth.txt:404: value 'nan'"},
      {"groundtruth_missing",
       [](const fs::path& d) { fs::remove(d / "groundtruth.txt"); },
       "INPUT/groundtruth.txt: not found"},
      {"image_missing",
       [](const fs::path& d) { fs::remove(d / "rgb" / "1000.466667.png"); },
       "INPUT/rgb.txt:24: image 'rgb/1000.466667.png' not found"},
      {"first_image_truncated",
       [first](const fs::path& d) { CutInHalf(d / first); },
       "999.800000.png: truncated PNG"},
      {"later_image_truncated",
       [](const fs::path& d) { CutInHalf(d / "rgb" / "1000.466667.png"); },
       "INPUT/rgb.txt:24: INPUT/rgb/1000.466667.png: truncated PNG"},
      {"first_image_header_huge",
       [first](const fs::path& d) { ClaimPngSize(d / first, 100000); },
       "999.800000.png: image size 100000x100000 exceeds the limit"},
  };
  test::RunCatalogue(kRoot, good.filename().string(),
                     "import tum INPUT -o OUT -q --preset fr1", cases);
}

TEST(BadImport, EurocSequences) {
  const fs::path good =
      standard_test::WriteEurocSequence(kRoot, "radial-tangential");
  const std::string cam = "INPUT/mav0/cam0/";
  const std::string gt = "INPUT/mav0/state_groundtruth_estimate0/data.csv:";
  const auto sensor = [](const std::string& from, const std::string& to) {
    return [from, to](const fs::path& d) {
      Replace(d / "mav0" / "cam0" / "sensor.yaml", from, to);
    };
  };
  const auto append_gt = [](const std::string& row) {
    return [row](const fs::path& d) {
      Append(d / "mav0" / "state_groundtruth_estimate0" / "data.csv", row);
    };
  };
  const std::vector<Case> cases = {
      {"image_list_backwards",
       [](const fs::path& d) {
         Append(d / "mav0" / "cam0" / "data.csv", "999000000,x.png\n");
       },
       cam + "data.csv:43: timestamp 0.999000000 does not increase"},
      {"groundtruth_backwards", append_gt("1000000,0,0,0,1,0,0,0\n"),
       gt + "343: timestamp does not increase"},
      {"groundtruth_short_row", append_gt("3000000000,1,2\n"),
       gt + "343: expected at least 8"},
      {"groundtruth_zero_quaternion", append_gt("3000000000,0,0,0,0,0,0,0\n"),
       gt + "343: quaternion is not unit length"},
      {"sensor_without_T_BS", sensor("T_BS:", "T_XX:"),
       cam + "sensor.yaml: field 'T_BS': missing"},
      {"sensor_intrinsics_wrong_node_kind",
       sensor("intrinsics: [70.5, 70.1, 39.2, 29.9]", "intrinsics: 5"),
       cam + "sensor.yaml: field 'intrinsics'"},
      {"sensor_resolution_wrong", sensor("[80, 60]", "[640, 480]"),
       cam + "sensor.yaml: field 'resolution': 640x480 but"},
      {"image_missing",
       [](const fs::path& d) {
         fs::remove(d / "mav0" / "cam0" / "data" / "1500000000.png");
       },
       cam + "data.csv:12: image '1500000000.png' not found"},
  };
  test::RunCatalogue(kRoot, good.filename().string(),
                     "import euroc INPUT -o OUT -q", cases);
}

TEST(BadImport, KittiSequences) {
  standard_test::WriteKittiSequence(kRoot);  // kRoot/dataset/...
  const std::string seq = "INPUT/sequences/07/";
  const auto at = [](const fs::path& d, const std::string& file) {
    return d / "sequences" / "07" / file;
  };
  const std::vector<Case> cases = {
      {"times_backwards",
       [at](const fs::path& d) {
         Replace(at(d, "times.txt"), "5.000000e-01", "1.000000e-02");
       },
       seq + "times.txt:6: timestamp 0.010000000 does not increase"},
      {"times_malformed",
       [at](const fs::path& d) {
         Replace(at(d, "times.txt"), "5.000000e-01", "half a second");
       },
       seq + "times.txt:6: 'half a second' is not a time"},
      {"poses_not_a_rotation",
       [](const fs::path& d) {
         const fs::path poses = d / "poses" / "07.txt";
         std::string text = ReadFileToString(poses);
         text.replace(0, text.find('\n'), "2 0 0 0 0 1 0 0 0 0 1 0");
         WriteFileAtomic(poses, text);
       },
       "INPUT/poses/07.txt:1: the 3x3 part is not a rotation matrix"},
      {"poses_one_missing",
       [](const fs::path& d) {
         const fs::path poses = d / "poses" / "07.txt";
         std::string text = ReadFileToString(poses);
         text.erase(text.rfind('\n', text.size() - 2) + 1);
         WriteFileAtomic(poses, text);
       },
       "INPUT/poses/07.txt: 19 poses but"},
      {"calib_without_P0",
       [at](const fs::path& d) { Replace(at(d, "calib.txt"), "P0:", "PX:"); },
       seq + "calib.txt: field 'P0': missing"},
      {"calib_short_P0",
       [at](const fs::path& d) {
         Replace(at(d, "calib.txt"), "P0: 70 0 40 0 0 70 30 0 0 0 1 0",
                 "P0: 70 0 40");
       },
       seq + "calib.txt:1: expected 12 numbers"},
      {"image_missing",
       [at](const fs::path& d) { fs::remove(at(d, "image_0/000005.png")); },
       seq + "times.txt:6: image 'image_0/000005.png' not found"},
      {"first_image_truncated",
       [at](const fs::path& d) { CutInHalf(at(d, "image_0/000000.png")); },
       "000000.png: truncated PNG"},
      {"later_image_truncated",
       [at](const fs::path& d) { CutInHalf(at(d, "image_0/000005.png")); },
       seq + "times.txt:6: " + seq + "image_0/000005.png: truncated PNG"},
  };
  test::RunCatalogue(kRoot, "dataset",
                     "import kitti INPUT/sequences/07 -o OUT -q --poses "
                     "INPUT/poses/07.txt",
                     cases);
}

}  // namespace
}  // namespace monomap
