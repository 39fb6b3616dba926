#include "monomap/io/rosbag2_import.h"

#include <sqlite3.h>
#include <yaml-cpp/yaml.h>

#include <functional>
#include <memory>
#include <optional>

#include "monomap/io/ros2_messages.h"
#include "monomap/util/error.h"

namespace monomap {
namespace fs = std::filesystem;

namespace {

// The bag's storage files, from metadata.yaml (or the lone .db3 given).
struct BagFiles {
  std::string name;  // what the user named, for messages
  std::vector<fs::path> db3;
};

std::string Field(const YAML::Node& info, const char* key) {
  const YAML::Node n = info[key];
  return n && n.IsScalar() ? n.as<std::string>() : "";
}

// Checks metadata.yaml: sqlite3 storage, no compression; lists the files.
BagFiles ReadMetadata(const fs::path& yaml, const std::string& name) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(yaml.string());
  } catch (const YAML::Exception& e) {
    throw InputError(yaml.string(), e.mark.line + 1, e.msg);
  }
  const YAML::Node info = root["rosbag2_bagfile_information"];
  if (!info || !info.IsMap()) {
    throw InputError(yaml.string(), "rosbag2_bagfile_information",
                     "missing: not a rosbag2 metadata.yaml");
  }
  const std::string storage = Field(info, "storage_identifier");
  if (storage != "sqlite3") {
    throw InputError(yaml.string(), "storage_identifier",
                     "'" + storage +
                         "' is not supported: only sqlite3 (.db3) bags are "
                         "read; convert with `ros2 bag convert` and a "
                         "storage_id: sqlite3 output");
  }
  const std::string compression = Field(info, "compression_format");
  if (!compression.empty()) {
    throw InputError(yaml.string(), "compression_format",
                     "'" + compression +
                         "': compressed bags are not supported; "
                         "decompress with `ros2 bag convert` first");
  }
  BagFiles files{name, {}};
  const YAML::Node paths = info["relative_file_paths"];
  if (paths && paths.IsSequence()) {
    for (const YAML::Node& p : paths) {
      files.db3.push_back(yaml.parent_path() / p.as<std::string>());
    }
  }
  if (files.db3.empty()) {
    throw InputError(yaml.string(), "relative_file_paths",
                     "lists no storage file");
  }
  for (const fs::path& f : files.db3) {
    if (!fs::is_regular_file(f)) {
      throw InputError(yaml.string(), "relative_file_paths",
                       f.string() + ": file not found");
    }
  }
  return files;
}

BagFiles FindFiles(const fs::path& path) {
  if (path.extension() == ".db3" && fs::is_regular_file(path)) {
    return {path.string(), {path}};
  }
  const fs::path yaml = fs::is_directory(path) ? path / "metadata.yaml" : path;
  if (!fs::is_regular_file(yaml)) {
    throw InputError(yaml.string() +
                     ": file not found (a ROS 2 bag directory holds "
                     "metadata.yaml; or give one .db3 file)");
  }
  return ReadMetadata(yaml, path.string());
}

// One .db3 file, open read-only.
class Db3 {
 public:
  explicit Db3(const fs::path& path) : path_(path.string()) {
    if (sqlite3_open_v2(path_.c_str(), &db_, SQLITE_OPEN_READONLY, nullptr) !=
        SQLITE_OK) {
      const std::string message = db_ ? sqlite3_errmsg(db_) : "out of memory";
      sqlite3_close(db_);
      throw InputError(path_ +
                       ": cannot open the ROS 2 bag storage: " + message);
    }
  }
  ~Db3() { sqlite3_close(db_); }
  Db3(const Db3&) = delete;
  Db3& operator=(const Db3&) = delete;

  // Runs `sql` (with one optional integer parameter) and calls `row` for
  // each result row; `row` returns false to stop.
  void Query(const char* sql, const std::optional<int64_t>& param,
             const std::function<bool(sqlite3_stmt*)>& row) {
    sqlite3_stmt* stmt = nullptr;
    if (sqlite3_prepare_v2(db_, sql, -1, &stmt, nullptr) != SQLITE_OK) {
      Fail("cannot read");
    }
    std::unique_ptr<sqlite3_stmt, int (*)(sqlite3_stmt*)> guard(
        stmt, sqlite3_finalize);
    if (param) sqlite3_bind_int64(stmt, 1, *param);
    int rc = SQLITE_ROW;
    while ((rc = sqlite3_step(stmt)) == SQLITE_ROW) {
      if (!row(stmt)) return;
    }
    if (rc != SQLITE_DONE) Fail("cannot read");
  }
  const std::string& path() const { return path_; }

 private:
  [[noreturn]] void Fail(const std::string& what) {
    throw InputError(path_ + ": " + what +
                     " the ROS 2 bag storage (truncated, corrupt or not a "
                     "sqlite3 .db3 file): " +
                     (db_ ? sqlite3_errmsg(db_) : "out of memory"));
  }
  std::string path_;
  sqlite3* db_ = nullptr;
};

std::string Text(sqlite3_stmt* stmt, int column) {
  const unsigned char* s = sqlite3_column_text(stmt, column);
  return s ? reinterpret_cast<const char*>(s) : "";
}

// A topic of one .db3 file.
struct Topic {
  int64_t id = 0;
  std::string type, serialization_format;
};

// The bag's .db3 files behind bag::BagMessages.
class Ros2Messages : public bag::BagMessages {
 public:
  explicit Ros2Messages(const BagFiles& files) : name_(files.name) {
    for (const fs::path& f : files.db3) {
      auto db = std::make_unique<Db3>(f);
      std::map<std::string, Topic> topics;
      db->Query("SELECT id, name, type, serialization_format FROM topics",
                std::nullopt, [&](sqlite3_stmt* s) {
                  topics[Text(s, 1)] = {sqlite3_column_int64(s, 0), Text(s, 2),
                                        Text(s, 3)};
                  return true;
                });
      files_.push_back({std::move(db), std::move(topics)});
    }
  }
  std::string Name() const override { return name_; }
  std::map<std::string, std::string> Topics() const override {
    std::map<std::string, std::string> types;
    for (const File& f : files_) {
      for (const auto& [name, topic] : f.topics) types[name] = topic.type;
    }
    return types;
  }
  void ForEachImage(const std::string& topic,
                    const std::function<bool(bag::Image&)>& visit) override {
    ForEachMessage(topic, [&](const Message& m) {
      const bool compressed =
          bag::CanonicalType(m.type) == "sensor_msgs/CompressedImage";
      bag::Image image =
          ros2::DecodeImage(m.data, m.size, compressed, m.recorded, m.where);
      return visit(image);
    });
  }
  void ForEachCameraInfo(
      const std::string& topic,
      const std::function<bool(const bag::CameraInfo&)>& visit) override {
    ForEachMessage(topic, [&](const Message& m) {
      return visit(ros2::DecodeCameraInfo(m.data, m.size, m.where));
    });
  }
  void ForEachTransform(
      const std::string& topic,
      const std::function<bool(const bag::Transform&)>& visit) override {
    ForEachMessage(topic, [&](const Message& m) {
      for (const bag::Transform& t :
           ros2::DecodeTfMessage(m.data, m.size, m.recorded, m.where)) {
        if (!visit(t)) return false;
      }
      return true;
    });
  }
  void ForEachOdometry(
      const std::string& topic,
      const std::function<bool(const bag::Transform&)>& visit) override {
    ForEachMessage(topic, [&](const Message& m) {
      return visit(ros2::DecodeOdometry(m.data, m.size, m.recorded, m.where));
    });
  }

 private:
  struct File {
    std::unique_ptr<Db3> db;
    std::map<std::string, Topic> topics;
  };
  struct Message {
    const uint8_t* data;
    size_t size;
    double recorded;  // s
    const std::string& type;
    const std::string& where;
  };

  // The topic's messages, file by file, in recording order.
  void ForEachMessage(const std::string& topic,
                      const std::function<bool(const Message&)>& visit) {
    for (File& f : files_) {
      const auto it = f.topics.find(topic);
      if (it == f.topics.end()) continue;
      const std::string where = f.db->path() + ": topic '" + topic + "'";
      if (it->second.serialization_format != "cdr") {
        throw InputError(
            where, "serialization_format",
            "'" + it->second.serialization_format + "' is not supported (cdr)");
      }
      bool go_on = true;
      f.db->Query(
          "SELECT timestamp, data FROM messages WHERE topic_id = ? "
          "ORDER BY timestamp, id",
          it->second.id, [&](sqlite3_stmt* s) {
            const auto* data =
                static_cast<const uint8_t*>(sqlite3_column_blob(s, 1));
            const size_t size = static_cast<size_t>(sqlite3_column_bytes(s, 1));
            go_on = visit({data, size, sqlite3_column_int64(s, 0) * 1e-9,
                           it->second.type, where});
            return go_on;
          });
      if (!go_on) return;
    }
  }

  std::string name_;
  std::vector<File> files_;
};

}  // namespace

bool IsRosbag2(const fs::path& path) {
  if (fs::is_directory(path)) {
    if (fs::exists(path / "metadata.yaml")) return true;
    for (const auto& entry : fs::directory_iterator(path)) {
      if (entry.path().extension() == ".db3") return true;
    }
    return false;
  }
  return path.extension() == ".db3" || path.filename() == "metadata.yaml";
}

RosbagImportReport ImportRosbag2(const fs::path& path, const fs::path& out_dir,
                                 const RosbagImportOptions& options) {
  options.Check();
  Ros2Messages messages(FindFiles(path));
  return bag::ImportBag(messages, out_dir, options);
}

}  // namespace monomap
