#include "monomap/io/ply.h"

#include <algorithm>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <sstream>

#include "monomap/util/error.h"
#include "monomap/util/file.h"

namespace monomap {

namespace {

static_assert(std::endian::native == std::endian::little,
              "binary PLY IO assumes a little-endian host");

enum class PlyType { kInt8, kUInt8, kInt16, kUInt16, kInt32, kUInt32,
                     kFloat32, kFloat64 };

bool ParsePlyType(const std::string& name, PlyType* type) {
  static const struct {
    const char* name;
    PlyType type;
  } kTypes[] = {
      {"char", PlyType::kInt8},     {"int8", PlyType::kInt8},
      {"uchar", PlyType::kUInt8},   {"uint8", PlyType::kUInt8},
      {"short", PlyType::kInt16},   {"int16", PlyType::kInt16},
      {"ushort", PlyType::kUInt16}, {"uint16", PlyType::kUInt16},
      {"int", PlyType::kInt32},     {"int32", PlyType::kInt32},
      {"uint", PlyType::kUInt32},   {"uint32", PlyType::kUInt32},
      {"float", PlyType::kFloat32}, {"float32", PlyType::kFloat32},
      {"double", PlyType::kFloat64}, {"float64", PlyType::kFloat64},
  };
  for (const auto& t : kTypes) {
    if (name == t.name) {
      *type = t.type;
      return true;
    }
  }
  return false;
}

size_t TypeSize(PlyType type) {
  switch (type) {
    case PlyType::kInt8:
    case PlyType::kUInt8:
      return 1;
    case PlyType::kInt16:
    case PlyType::kUInt16:
      return 2;
    case PlyType::kInt32:
    case PlyType::kUInt32:
    case PlyType::kFloat32:
      return 4;
    case PlyType::kFloat64:
      return 8;
  }
  return 0;
}

template <typename T>
double LoadAs(const char* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  return static_cast<double>(v);
}

// Value of a binary scalar of `type` stored at p (little endian).
double LoadBinary(PlyType type, const char* p) {
  switch (type) {
    case PlyType::kInt8: return LoadAs<int8_t>(p);
    case PlyType::kUInt8: return LoadAs<uint8_t>(p);
    case PlyType::kInt16: return LoadAs<int16_t>(p);
    case PlyType::kUInt16: return LoadAs<uint16_t>(p);
    case PlyType::kInt32: return LoadAs<int32_t>(p);
    case PlyType::kUInt32: return LoadAs<uint32_t>(p);
    case PlyType::kFloat32: return LoadAs<float>(p);
    case PlyType::kFloat64: return LoadAs<double>(p);
  }
  return 0.0;
}

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::kFloat32;  // value type (of the items, for lists)
  bool is_list = false;
  PlyType count_type = PlyType::kUInt8;  // lists only
};

struct PlyElement {
  std::string name;
  int64_t count = 0;
  std::vector<PlyProperty> properties;
};

enum class PlyFormat { kAscii, kBinaryLittleEndian };

struct PlyHeader {
  PlyFormat format = PlyFormat::kAscii;
  std::vector<PlyElement> elements;
  size_t data_start = 0;  // byte offset of the first data byte
};

// Fewest bytes one row of `element` can take: binary, its scalars and list
// lengths; ASCII, one character and a separator per value.
uint64_t MinRowBytes(const PlyElement& element, PlyFormat format) {
  uint64_t bytes = 0;
  for (const PlyProperty& p : element.properties) {
    bytes += format == PlyFormat::kAscii
                 ? 2
                 : TypeSize(p.is_list ? p.count_type : p.type);
  }
  return bytes;
}

// Bounds every element count by the data actually present, before any
// loop or allocation: a small file cannot claim billions of rows.
void CheckElementCounts(const PlyHeader& header, size_t data_bytes,
                        const std::string& file) {
  for (const PlyElement& element : header.elements) {
    const uint64_t row_bytes = MinRowBytes(element, header.format);
    const uint64_t count = static_cast<uint64_t>(element.count);
    if (row_bytes == 0 && count > 0) {
      throw InputError(file + ": PLY element '" + element.name + "' has " +
                       std::to_string(count) + " rows but no properties");
    }
    // ASCII: the last value needs no separator.
    const uint64_t slack = header.format == PlyFormat::kAscii ? 1 : 0;
    if (row_bytes > 0 && count > (data_bytes + slack) / row_bytes) {
      throw InputError(file + ": truncated PLY or bad count: element '" +
                       element.name + "' count " + std::to_string(count) +
                       " needs at least " + std::to_string(row_bytes) +
                       " bytes per row, the file "
                       "has only " +
                       std::to_string(data_bytes) + " bytes of data");
    }
  }
}

// The header lines below: "format FORMAT 1.0", "element NAME COUNT",
// "property TYPE NAME" or "property list COUNT_TYPE TYPE NAME" (tokens,
// at line_number of file).
PlyFormat ParseFormatLine(const std::vector<std::string>& tokens,
                          const std::string& file, int line_number) {
  if (tokens.size() != 3) {
    throw InputError(file, line_number, "malformed PLY format line");
  }
  if (tokens[1] == "ascii") return PlyFormat::kAscii;
  if (tokens[1] == "binary_little_endian") {
    return PlyFormat::kBinaryLittleEndian;
  }
  throw InputError(file, line_number,
                   "unsupported PLY format '" + tokens[1] +
                       "' (ascii or binary_little_endian)");
}

PlyElement ParseElementLine(const std::vector<std::string>& tokens,
                            const std::string& file, int line_number) {
  PlyElement element;
  if (tokens.size() != 3) {
    throw InputError(file, line_number, "malformed PLY element line");
  }
  element.name = tokens[1];
  const char* end = tokens[2].data() + tokens[2].size();
  const auto r = std::from_chars(tokens[2].data(), end, element.count);
  if (r.ec != std::errc() || r.ptr != end || element.count < 0) {
    throw InputError(file, line_number,
                     "bad element count '" + tokens[2] + "'");
  }
  return element;
}

PlyProperty ParsePropertyLine(const std::vector<std::string>& tokens,
                              const std::string& line, const std::string& file,
                              int line_number) {
  PlyProperty property;
  bool ok = false;
  if (tokens.size() == 5 && tokens[1] == "list") {
    property.is_list = true;
    ok = ParsePlyType(tokens[2], &property.count_type) &&
         ParsePlyType(tokens[3], &property.type);
    // A list length must be an integer.
    ok = ok && property.count_type != PlyType::kFloat32 &&
         property.count_type != PlyType::kFloat64;
    property.name = tokens[4];
  } else if (tokens.size() == 3) {
    ok = ParsePlyType(tokens[1], &property.type);
    property.name = tokens[2];
  }
  if (!ok) {
    throw InputError(file, line_number,
                     "malformed or unsupported PLY property '" + line + "'");
  }
  return property;
}

PlyHeader ParseHeader(const std::string& data, const std::string& file) {
  PlyHeader header;
  size_t pos = 0;
  int line_number = 0;
  bool have_format = false;
  auto next_line = [&](std::string* line) {
    if (pos >= data.size()) return false;
    size_t end = data.find('\n', pos);
    if (end == std::string::npos) end = data.size();
    *line = data.substr(pos, end - pos);
    if (!line->empty() && line->back() == '\r') line->pop_back();
    pos = std::min(end + 1, data.size());
    ++line_number;
    return true;
  };
  std::string line;
  if (!next_line(&line) || line != "ply") {
    throw InputError(file + ": not a PLY file (first line is not 'ply')");
  }
  while (true) {
    if (!next_line(&line)) {
      throw InputError(file + ": PLY header has no 'end_header'");
    }
    const auto tokens = SplitWhitespace(line);
    if (tokens.empty()) continue;
    const std::string& keyword = tokens[0];
    if (keyword == "end_header") break;
    if (keyword == "comment" || keyword == "obj_info") continue;
    if (keyword == "format") {
      header.format = ParseFormatLine(tokens, file, line_number);
      have_format = true;
    } else if (keyword == "element") {
      header.elements.push_back(ParseElementLine(tokens, file, line_number));
    } else if (keyword == "property") {
      if (header.elements.empty()) {
        throw InputError(file, line_number,
                         "PLY property before any element");
      }
      header.elements.back().properties.push_back(
          ParsePropertyLine(tokens, line, file, line_number));
    } else {
      throw InputError(file, line_number,
                       "unknown PLY header keyword '" + keyword + "'");
    }
  }
  if (!have_format) throw InputError(file + ": PLY header has no format");
  header.data_start = pos;
  CheckElementCounts(header, data.size() - pos, file);
  return header;
}

// Reads the data section and returns, for each name in `wanted`, the
// column of that scalar vertex property (empty if the vertex element has no
// such property).
class PlyDataReader {
 public:
  PlyDataReader(const std::string& data, const PlyHeader& header,
                std::string file)
      : data_(data), header_(header), file_(std::move(file)),
        pos_(header.data_start) {}

  std::vector<std::vector<double>> ReadVertexColumns(
      const std::vector<std::string>& wanted) {
    // Which wanted column each vertex property fills (-1: skipped).
    const PlyElement* vertex = nullptr;
    for (const PlyElement& element : header_.elements) {
      if (element.name == "vertex") {
        vertex = &element;
        break;
      }
    }
    if (vertex == nullptr) {
      throw InputError(file_ + ": PLY file has no vertex element");
    }
    std::vector<int> target(vertex->properties.size(), -1);
    for (size_t p = 0; p < vertex->properties.size(); ++p) {
      for (size_t w = 0; w < wanted.size(); ++w) {
        if (vertex->properties[p].name == wanted[w]) {
          if (vertex->properties[p].is_list) {
            throw InputError(file_ + ": PLY vertex property '" + wanted[w] +
                             "' is a list, expected a scalar");
          }
          target[p] = static_cast<int>(w);
        }
      }
    }
    std::vector<std::vector<double>> columns(wanted.size());
    for (const PlyElement& element : header_.elements) {
      const bool is_vertex = &element == vertex;
      if (is_vertex) {
        // Guard the reservation against absurd counts in corrupt headers.
        const int64_t max_rows =
            static_cast<int64_t>(data_.size() - std::min(pos_, data_.size()));
        const int64_t reserve = std::min<int64_t>(element.count, max_rows);
        for (size_t w = 0; w < wanted.size(); ++w) {
          bool present = false;
          for (int t : target) present = present || t == static_cast<int>(w);
          if (present) columns[w].reserve(static_cast<size_t>(reserve));
        }
      }
      if (header_.format == PlyFormat::kBinaryLittleEndian &&
          IsFixedSize(element)) {
        ReadFixedBinary(element, is_vertex ? &target : nullptr, &columns);
      } else {
        for (int64_t row = 0; row < element.count; ++row) {
          for (size_t p = 0; p < element.properties.size(); ++p) {
            const PlyProperty& property = element.properties[p];
            if (property.is_list) {
              const double n = ReadValue(property.count_type, element, row);
              if (n < 0 || n != std::floor(n)) {
                Fail(element, row, "negative or non-integer list length");
              }
              // Checked as a double: a cast of an out-of-range value to an
              // integer is undefined. Each item takes at least one byte.
              if (n > static_cast<double>(data_.size() - pos_)) {
                Fail(element, row,
                     "list length " + std::to_string(n) +
                         " exceeds the data left in the file");
              }
              for (int64_t k = 0; k < static_cast<int64_t>(n); ++k) {
                ReadValue(property.type, element, row);
              }
            } else {
              const double v = ReadValue(property.type, element, row);
              if (is_vertex && target[p] >= 0) columns[target[p]].push_back(v);
            }
          }
        }
      }
      if (is_vertex) break;  // nothing after the vertices is needed
    }
    return columns;
  }

 private:
  static bool IsFixedSize(const PlyElement& element) {
    for (const auto& p : element.properties) {
      if (p.is_list) return false;
    }
    return true;
  }

  [[noreturn]] void Fail(const PlyElement& element, int64_t row,
                         const std::string& what) const {
    throw InputError(file_ + ": " + what + " in element '" + element.name +
                     "' row " + std::to_string(row) + " of " +
                     std::to_string(element.count));
  }

  // Binary element without lists: fixed stride, checked once for
  // truncation, then read directly.
  void ReadFixedBinary(const PlyElement& element, const std::vector<int>* target,
                       std::vector<std::vector<double>>* columns) {
    size_t stride = 0;
    std::vector<size_t> offsets;
    for (const auto& p : element.properties) {
      offsets.push_back(stride);
      stride += TypeSize(p.type);
    }
    const size_t available = data_.size() - std::min(pos_, data_.size());
    if (stride > 0 &&
        static_cast<uint64_t>(element.count) > available / stride) {
      throw InputError(file_ + ": truncated PLY data: element '" +
                       element.name + "' needs " +
                       std::to_string(element.count) + " rows of " +
                       std::to_string(stride) + " bytes, only " +
                       std::to_string(available) + " bytes left");
    }
    if (target != nullptr) {
      const char* base = data_.data() + pos_;
      for (size_t p = 0; p < element.properties.size(); ++p) {
        const int w = (*target)[p];
        if (w < 0) continue;
        auto& column = (*columns)[w];
        const PlyType type = element.properties[p].type;
        for (int64_t row = 0; row < element.count; ++row) {
          column.push_back(LoadBinary(type, base + row * stride + offsets[p]));
        }
      }
    }
    pos_ += static_cast<size_t>(element.count) * stride;
  }

  double ReadValue(PlyType type, const PlyElement& element, int64_t row) {
    if (header_.format == PlyFormat::kBinaryLittleEndian) {
      const size_t size = TypeSize(type);
      if (pos_ + size > data_.size()) Fail(element, row, "truncated PLY data");
      const double v = LoadBinary(type, data_.data() + pos_);
      pos_ += size;
      return v;
    }
    // ASCII: next white-space separated token.
    while (pos_ < data_.size() &&
           std::isspace(static_cast<unsigned char>(data_[pos_]))) {
      ++pos_;
    }
    if (pos_ >= data_.size()) Fail(element, row, "truncated PLY data");
    size_t end = pos_;
    while (end < data_.size() &&
           !std::isspace(static_cast<unsigned char>(data_[end]))) {
      ++end;
    }
    double v = 0.0;
    const auto r = std::from_chars(data_.data() + pos_, data_.data() + end, v);
    if (r.ec != std::errc() || r.ptr != data_.data() + end ||
        !std::isfinite(v)) {
      Fail(element, row,
           "bad PLY value '" + data_.substr(pos_, end - pos_) + "'");
    }
    pos_ = end;
    return v;
  }

  const std::string& data_;
  const PlyHeader& header_;
  std::string file_;
  size_t pos_;
};

std::vector<std::vector<double>> ReadVertexColumns(
    const std::filesystem::path& path, const std::vector<std::string>& wanted,
    size_t num_required) {
  const std::string file = path.string();
  const std::string data = ReadFileToString(path);
  const PlyHeader header = ParseHeader(data, file);
  PlyDataReader reader(data, header, file);
  auto columns = reader.ReadVertexColumns(wanted);
  int64_t count = 0;
  for (const auto& element : header.elements) {
    if (element.name == "vertex") count = element.count;
  }
  for (size_t w = 0; w < num_required; ++w) {
    if (columns[w].size() != static_cast<size_t>(count)) {
      throw InputError(file + ": PLY vertex element has no property '" +
                       wanted[w] + "'");
    }
  }
  return columns;
}

// An integer id read as a double, checked to lie in [lo, hi] before the
// cast (out of range, the cast would be undefined).
double CheckedId(double v, double lo, double hi,
                 const std::filesystem::path& path, const char* field,
                 size_t row) {
  if (!(v >= lo && v <= hi) || v != std::floor(v)) {
    throw InputError(path.string() + ": vertex " + std::to_string(row) + ": '" +
                     field + "' " + std::to_string(v) +
                     " is not an integer in [" + std::to_string(lo) + ", " +
                     std::to_string(hi) + "]");
  }
  return v;
}

// A per-point quality value read as a double, checked to be finite and in
// [0, hi].
double CheckedQuality(double v, double hi, const std::filesystem::path& path,
                      const char* field, size_t row) {
  if (!(v >= 0.0 && v <= hi)) {
    throw InputError(path.string() + ": vertex " + std::to_string(row) + ": '" +
                     field + "' " + std::to_string(v) + " is not in [0, " +
                     std::to_string(hi) + "]");
  }
  return v;
}

// The quality columns (track_length, reprojection_error_px,
// triangulation_angle_deg) of vertex i, each when present.
void SetPointQuality(const std::vector<std::vector<double>>& columns, size_t i,
                     const std::filesystem::path& path, Landmark* l) {
  const size_t n = columns[0].size();
  if (columns[8].size() == n) {
    l->num_observations = static_cast<int>(
        CheckedId(columns[8][i], 0, std::numeric_limits<int>::max(), path,
                  "track_length", i));
  }
  if (columns[9].size() == n) {
    l->mean_reprojection_error_px =
        CheckedQuality(columns[9][i], std::numeric_limits<float>::max(), path,
                       "reprojection_error_px", i);
  }
  if (columns[10].size() == n) {
    l->triangulation_angle_deg = CheckedQuality(columns[10][i], 180.0, path,
                                                "triangulation_angle_deg", i);
  }
}

}  // namespace

std::vector<Eigen::Vector3d> ReadPlyPoints(const std::filesystem::path& path) {
  const auto columns = ReadVertexColumns(path, {"x", "y", "z"}, 3);
  std::vector<Eigen::Vector3d> points(columns[0].size());
  for (size_t i = 0; i < points.size(); ++i) {
    points[i] = {columns[0][i], columns[1][i], columns[2][i]};
  }
  return points;
}

std::vector<Landmark> ReadLandmarksPly(const std::filesystem::path& path) {
  const auto columns = ReadVertexColumns(
      path,
      {"x", "y", "z", "red", "green", "blue", "feature_id", "plane",
       "track_length", "reprojection_error_px", "triangulation_angle_deg"},
      3);
  const size_t n = columns[0].size();
  const bool has_color =
      columns[3].size() == n && columns[4].size() == n && columns[5].size() == n;
  std::vector<Landmark> landmarks(n);
  for (size_t i = 0; i < n; ++i) {
    Landmark& l = landmarks[i];
    l.x_in_world = {columns[0][i], columns[1][i], columns[2][i]};
    if (has_color) {
      l.color = Eigen::Vector3d(columns[3][i], columns[4][i], columns[5][i])
                    .cast<float>();
    }
    l.id = columns[6].size() == n
               ? static_cast<FeatureId>(
                     CheckedId(columns[6][i], 0, 9.0e15, path, "feature_id", i))
               : static_cast<FeatureId>(i);
    l.plane_id = columns[7].size() == n
                     ? static_cast<int>(CheckedId(
                           columns[7][i], -1, std::numeric_limits<int>::max(),
                           path, "plane", i))
                     : -1;
    SetPointQuality(columns, i, path, &l);
  }
  return landmarks;
}

void WriteLandmarksPly(const std::filesystem::path& path,
                       const std::vector<Landmark>& landmarks) {
  std::ostringstream header;
  header << "ply\n"
         << "format binary_little_endian 1.0\n"
         << "comment monomap landmarks (world frame, metres)\n"
         << "element vertex " << landmarks.size() << "\n"
         << "property float x\nproperty float y\nproperty float z\n"
         << "property uchar red\nproperty uchar green\nproperty uchar blue\n"
         << "property int feature_id\nproperty int plane\n"
         << "property int track_length\n"
         << "property float reprojection_error_px\n"
         << "property float triangulation_angle_deg\n"
         << "end_header\n";
  constexpr size_t kStride = 3 * 4 + 3 + 4 + 4 + 4 + 4 + 4;
  std::string out = header.str();
  const size_t start = out.size();
  out.resize(start + landmarks.size() * kStride);
  char* p = out.data() + start;
  for (const Landmark& l : landmarks) {
    if (l.id < std::numeric_limits<int32_t>::min() ||
        l.id > std::numeric_limits<int32_t>::max()) {
      throw OutputError(path.string() + ": feature id " +
                        std::to_string(l.id) +
                        " does not fit the PLY int property");
    }
    // What ReadLandmarksPly would refuse is refused here, before writing.
    if (l.num_observations < 0 ||
        !(l.mean_reprojection_error_px >= 0.0 &&
          l.mean_reprojection_error_px <= std::numeric_limits<float>::max()) ||
        !(l.triangulation_angle_deg >= 0.0 &&
          l.triangulation_angle_deg <= 180.0)) {
      throw OutputError(path.string() + ": landmark " + std::to_string(l.id) +
                        " has an invalid track length, reprojection error "
                        "or triangulation angle");
    }
    const float xyz[3] = {static_cast<float>(l.x_in_world.x()),
                          static_cast<float>(l.x_in_world.y()),
                          static_cast<float>(l.x_in_world.z())};
    std::memcpy(p, xyz, sizeof(xyz));
    p += sizeof(xyz);
    for (int c = 0; c < 3; ++c) {
      const float v = std::isfinite(l.color[c]) ? l.color[c] : 0.0f;
      *p++ = static_cast<char>(
          static_cast<uint8_t>(std::lround(std::clamp(v, 0.0f, 255.0f))));
    }
    const int32_t ids[3] = {static_cast<int32_t>(l.id),
                            static_cast<int32_t>(l.plane_id),
                            static_cast<int32_t>(l.num_observations)};
    std::memcpy(p, ids, sizeof(ids));
    p += sizeof(ids);
    const float quality[2] = {static_cast<float>(l.mean_reprojection_error_px),
                              static_cast<float>(l.triangulation_angle_deg)};
    std::memcpy(p, quality, sizeof(quality));
    p += sizeof(quality);
  }
  WriteFileAtomic(path, out);
}

}  // namespace monomap
