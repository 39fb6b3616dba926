// Test helper: writes ROS 2 bags in the sqlite3 storage as `ros2 bag
// record` lays them out (a directory with metadata.yaml and one .db3 with
// the tables topics and messages), the messages CDR-serialized with
// fastcdr. Implements the sink of bag_test::LogDrive.
#pragma once

#include <fastcdr/Cdr.h>
#include <fastcdr/FastBuffer.h>
#include <sqlite3.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "monomap/camera/camera.h"
#include "monomap/geometry/rigid3.h"

namespace monomap::rosbag2_test {

// One CDR message under construction (little-endian, as ROS 2 writes).
class CdrWriter {
 public:
  explicit CdrWriter(bool big_endian = false)
      : cdr_(buffer_,
             big_endian ? eprosima::fastcdr::Cdr::BIG_ENDIANNESS
                        : eprosima::fastcdr::Cdr::LITTLE_ENDIANNESS,
             eprosima::fastcdr::Cdr::DDS_CDR) {
    cdr_.serialize_encapsulation();
  }
  template <typename T>
  CdrWriter& operator<<(const T& v) {
    cdr_.serialize(v);
    return *this;
  }
  void Header(double stamp, const std::string& frame) {
    const double sec = std::floor(stamp);
    *this << int32_t(sec) << uint32_t(std::lround((stamp - sec) * 1e9))
          << frame;
  }
  void Bytes(const std::vector<uint8_t>& data) {
    *this << uint32_t(data.size());
    if (!data.empty()) cdr_.serializeArray(data.data(), data.size());
  }
  void Doubles(const double* v, size_t n) { cdr_.serializeArray(v, n); }
  void Pose(const Rigid3d& t) {
    const double v[7] = {
        t.translation.x(), t.translation.y(), t.translation.z(), t.rotation.x(),
        t.rotation.y(),    t.rotation.z(),    t.rotation.w()};
    Doubles(v, 7);
  }
  std::string Data() {
    return std::string(cdr_.getBufferPointer(), cdr_.getSerializedDataLength());
  }

 private:
  eprosima::fastcdr::FastBuffer buffer_;
  eprosima::fastcdr::Cdr cdr_;
};

class Ros2BagWriter {
 public:
  // Creates `dir`/bag_0.db3; metadata.yaml is written by Close().
  explicit Ros2BagWriter(std::filesystem::path dir) : dir_(std::move(dir)) {
    std::filesystem::create_directories(dir_);
    const std::string db3 = (dir_ / "bag_0.db3").string();
    std::filesystem::remove(db3);
    Check(sqlite3_open(db3.c_str(), &db_));
    Exec("PRAGMA synchronous = OFF");  // test data: no fsync per message
    Exec(
        "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, "
        "type TEXT NOT NULL, serialization_format TEXT NOT NULL, "
        "offered_qos_profiles TEXT NOT NULL);"
        "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT "
        "NULL, timestamp INTEGER NOT NULL, data BLOB NOT NULL);"
        "CREATE INDEX timestamp_idx ON messages (timestamp ASC);");
  }
  ~Ros2BagWriter() { Close(); }

  // Every message of `topic` is written with `format` (cdr normally).
  void Write(const std::string& topic, const std::string& type, double t,
             const std::string& data, const std::string& format = "cdr") {
    if (!topics_.count(topic)) {
      const int id = static_cast<int>(topics_.size()) + 1;
      topics_[topic] = {id, type, format, 0};
      Exec("INSERT INTO topics VALUES(" + std::to_string(id) + ", '" + topic +
           "', '" + type + "', '" + format + "', '')");
    }
    auto& info = topics_[topic];
    ++info.count;
    sqlite3_stmt* stmt = nullptr;
    Check(sqlite3_prepare_v2(
        db_, "INSERT INTO messages(topic_id, timestamp, data) VALUES(?,?,?)",
        -1, &stmt, nullptr));
    sqlite3_bind_int(stmt, 1, info.id);
    sqlite3_bind_int64(stmt, 2, std::llround(t * 1e9));
    sqlite3_bind_blob(stmt, 3, data.data(), static_cast<int>(data.size()),
                      SQLITE_TRANSIENT);
    const int rc = sqlite3_step(stmt);
    sqlite3_finalize(stmt);
    if (rc != SQLITE_DONE) throw std::runtime_error(sqlite3_errmsg(db_));
  }

  // The sink of bag_test::LogDrive.
  void CameraInfo(const std::string& topic, double t, const Camera& c,
                  const std::string& model, bool calibrated) {
    CdrWriter w;
    w.Header(t, "camera_optical");
    w << uint32_t(c.height) << uint32_t(c.width) << model;
    const size_t n = c.model == LensModel::kEquidistant ? 4 : 5;
    w << uint32_t(n);
    w.Doubles(c.distortion.data(), n);
    const double f = calibrated ? 1.0 : 0.0;
    const double k[9] = {f * c.fx, 0, c.cx, 0, f * c.fy, c.cy, 0, 0, 1};
    const double r[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    const double p[12] = {f * c.fx, 0, c.cx, 0, 0, f * c.fy,
                          c.cy,     0, 0,    0, 1, 0};
    w.Doubles(k, 9);
    w.Doubles(r, 9);
    w.Doubles(p, 12);
    // binning_x, binning_y, roi (x_offset, y_offset, height, width,
    // do_rectify).
    w << uint32_t(0) << uint32_t(0) << uint32_t(0) << uint32_t(0) << uint32_t(0)
      << uint32_t(0) << false;
    Write(topic, "sensor_msgs/msg/CameraInfo", t, w.Data());
  }
  void Tf(const std::string& topic, double recorded, double stamp,
          const std::string& parent, const std::string& child,
          const Rigid3d& parent_from_child) {
    CdrWriter w;
    w << uint32_t(1);
    w.Header(stamp, parent);
    w << child;
    w.Pose(parent_from_child);
    Write(topic, "tf2_msgs/msg/TFMessage", recorded, w.Data());
  }
  void Odometry(const std::string& topic, double t, const std::string& parent,
                const std::string& child, const Rigid3d& odom_from_base) {
    CdrWriter w;
    w.Header(t, parent);
    w << child;
    w.Pose(odom_from_base);
    const std::vector<double> zeros(36 + 6 + 36, 0.0);  // cov, twist, cov
    w.Doubles(zeros.data(), zeros.size());
    Write(topic, "nav_msgs/msg/Odometry", t, w.Data());
  }
  void Image(const std::string& topic, double t, const std::string& frame,
             const cv::Mat& image, const std::string& encoding) {
    cv::Mat pixels = image;
    if (encoding == "rgb8") cv::cvtColor(image, pixels, cv::COLOR_BGR2RGB);
    pixels = pixels.isContinuous() ? pixels : pixels.clone();
    const uint32_t step = image.cols * image.elemSize();
    CdrWriter w;
    w.Header(t, frame);
    w << uint32_t(image.rows) << uint32_t(image.cols) << encoding << uint8_t(0)
      << step;
    w.Bytes(std::vector<uint8_t>(pixels.data, pixels.data + step * image.rows));
    Write(topic, "sensor_msgs/msg/Image", t, w.Data());
  }
  void Compressed(const std::string& topic, double t, const std::string& frame,
                  const cv::Mat& image, const std::string& ext) {
    std::vector<uint8_t> bytes;
    cv::imencode(ext, image, bytes);
    CdrWriter w;
    w.Header(t, frame);
    w << std::string(ext == ".png" ? "png" : "jpeg");
    w.Bytes(bytes);
    Write(topic, "sensor_msgs/msg/CompressedImage", t, w.Data());
  }

  // Closes the database and writes metadata.yaml with `storage`.
  void Close(const std::string& storage = "sqlite3") {
    if (!db_) return;
    sqlite3_close(db_);
    db_ = nullptr;
    std::ofstream yaml(dir_ / "metadata.yaml");
    yaml << "rosbag2_bagfile_information:\n  version: 5\n"
         << "  storage_identifier: " << storage << "\n"
         << "  relative_file_paths:\n    - bag_0.db3\n"
         << "  duration:\n    nanoseconds: 0\n"
         << "  starting_time:\n    nanoseconds_since_epoch: 0\n"
         << "  message_count: 0\n  topics_with_message_count:\n";
    for (const auto& [name, info] : topics_) {
      yaml << "    - topic_metadata:\n        name: " << name
           << "\n        type: " << info.type
           << "\n        serialization_format: " << info.format
           << "\n        offered_qos_profiles: \"\"\n"
           << "      message_count: " << info.count << "\n";
    }
    yaml << "  compression_format: \"\"\n  compression_mode: \"\"\n";
  }

 private:
  struct TopicInfo {
    int id;
    std::string type, format;
    int count;
  };
  void Check(int rc) {
    if (rc != SQLITE_OK) throw std::runtime_error(sqlite3_errstr(rc));
  }
  void Exec(const std::string& sql) {
    Check(sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, nullptr));
  }
  std::filesystem::path dir_;
  sqlite3* db_ = nullptr;
  std::map<std::string, TopicInfo> topics_;
};

}  // namespace monomap::rosbag2_test
