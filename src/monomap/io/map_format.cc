#include "monomap/io/map_format.h"

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <set>

#include "monomap/io/gltf.h"
#include "monomap/io/image_file.h"
#include "monomap/io/ply.h"
#include "monomap/io/trajectory_io.h"
#include "monomap/util/error.h"
#include "monomap/util/file.h"

namespace monomap {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// Written with insertion order kept, so "format" and "version" come first.
using OrderedJson = nlohmann::ordered_json;

OrderedJson VectorJson(const Eigen::Vector3d& v) {
  return {v.x(), v.y(), v.z()};
}
OrderedJson VectorJson(const Eigen::Vector2d& v) { return {v.x(), v.y()}; }

// The texture as 8-bit BGRA (what the format stores), or an empty Mat if it
// cannot be converted.
cv::Mat ToBgra(const cv::Mat& texture) {
  if (texture.empty() || texture.depth() != CV_8U) return {};
  cv::Mat bgra;
  switch (texture.channels()) {
    case 4:
      return texture;
    case 3:
      cv::cvtColor(texture, bgra, cv::COLOR_BGR2BGRA);
      return bgra;
    case 1:
      cv::cvtColor(texture, bgra, cv::COLOR_GRAY2BGRA);
      return bgra;
    default:
      return {};
  }
}

// Typed access to map.json fields; every error names the file and the
// field path.
class JsonFields {
 public:
  explicit JsonFields(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void Fail(const std::string& field,
                         const std::string& what) const {
    throw InputError(file_, field, what);
  }

  static std::string Join(const std::string& parent, const std::string& key) {
    return parent.empty() ? key : parent + "." + key;
  }
  static std::string Index(const std::string& parent, size_t i) {
    return parent + "[" + std::to_string(i) + "]";
  }

  const json& Get(const json& object, const std::string& parent,
                  const std::string& key) const {
    const auto it = object.find(key);
    if (it == object.end()) Fail(Join(parent, key), "missing");
    return *it;
  }

  double Number(const json& value, const std::string& field) const {
    if (!value.is_number()) Fail(field, "expected a number");
    const double v = value.get<double>();
    if (!std::isfinite(v)) Fail(field, "not finite");
    return v;
  }
  double Number(const json& object, const std::string& parent,
                const std::string& key) const {
    return Number(Get(object, parent, key), Join(parent, key));
  }

  int64_t Integer(const json& object, const std::string& parent,
                  const std::string& key) const {
    const json& value = Get(object, parent, key);
    if (!value.is_number_integer()) {
      Fail(Join(parent, key), "expected an integer");
    }
    if (value.is_number_unsigned() &&
        value.get<uint64_t>() >
            static_cast<uint64_t>(std::numeric_limits<int64_t>::max())) {
      Fail(Join(parent, key), "out of range");
    }
    return value.get<int64_t>();
  }

  int Int(const json& object, const std::string& parent,
          const std::string& key) const {
    const int64_t v = Integer(object, parent, key);
    if (v < std::numeric_limits<int>::min() ||
        v > std::numeric_limits<int>::max()) {
      Fail(Join(parent, key), "out of range");
    }
    return static_cast<int>(v);
  }

  std::string String(const json& object, const std::string& parent,
                     const std::string& key) const {
    const json& value = Get(object, parent, key);
    if (!value.is_string()) Fail(Join(parent, key), "expected a string");
    return value.get<std::string>();
  }

  const json& Array(const json& value, const std::string& field) const {
    if (!value.is_array()) Fail(field, "expected an array");
    return value;
  }
  const json& Array(const json& object, const std::string& parent,
                    const std::string& key) const {
    return Array(Get(object, parent, key), Join(parent, key));
  }

  // An array of exactly N numbers.
  template <int N>
  Eigen::Matrix<double, N, 1> Vector(const json& value,
                                     const std::string& field) const {
    Array(value, field);
    if (value.size() != N) {
      Fail(field, "expected " + std::to_string(N) + " numbers, got " +
                      std::to_string(value.size()));
    }
    Eigen::Matrix<double, N, 1> v;
    for (int i = 0; i < N; ++i) v[i] = Number(value[i], Index(field, i));
    return v;
  }
  template <int N>
  Eigen::Matrix<double, N, 1> Vector(const json& object,
                                     const std::string& parent,
                                     const std::string& key) const {
    return Vector<N>(Get(object, parent, key), Join(parent, key));
  }

  const std::string& file() const { return file_; }

 private:
  std::string file_;
};

// The camera object under `key` ("camera", or "given_camera").
Camera ReadCamera(const JsonFields& f, const json& root,
                  const std::string& key) {
  const json& c = f.Get(root, "", key);
  if (!c.is_object()) f.Fail(key, "expected an object");
  Camera camera;
  camera.width = f.Int(c, key, "width");
  camera.height = f.Int(c, key, "height");
  camera.fx = f.Number(c, key, "fx");
  camera.fy = f.Number(c, key, "fy");
  camera.cx = f.Number(c, key, "cx");
  camera.cy = f.Number(c, key, "cy");
  const auto d = f.Vector<5>(c, key, "distortion");
  for (int i = 0; i < 5; ++i) camera.distortion[i] = d[i];
  // "model" is written only for lenses other than plumb_bob, so maps of a
  // plumb_bob camera read and write as before.
  if (c.contains("model")) {
    const std::string name = f.String(c, key, "model");
    const auto model = LensModelFromName(name);
    if (!model) {
      f.Fail(key + ".model",
             "'" + name + "' is not supported (plumb_bob or equidistant)");
    }
    camera.model = *model;
  }
  if (camera.width <= 0 || camera.height <= 0) {
    f.Fail(key + (camera.width <= 0 ? ".width" : ".height"),
           "must be positive");
  }
  // Checked before anything allocates an image of the camera's size.
  const std::string size_error =
      ImageSizeLimitError(camera.width, camera.height);
  if (!size_error.empty()) f.Fail(key, size_error);
  if (camera.fx <= 0) f.Fail(key + ".fx", "must be positive");
  if (camera.fy <= 0) f.Fail(key + ".fy", "must be positive");
  return camera;
}

// The plane frame's axes and origin, checked against the plane read
// already: unit axes in the plane, orthogonal, origin on the plane.
void ReadPlaneFrame(const JsonFields& f, const json& p,
                    const std::string& field, TexturedPlane* plane) {
  plane->frame.origin = f.Vector<3>(p, field, "origin");
  plane->frame.u_axis = f.Vector<3>(p, field, "u_axis");
  plane->frame.v_axis = f.Vector<3>(p, field, "v_axis");
  const Eigen::Vector3d& n = plane->plane.normal;
  const struct {
    const char* key;
    const Eigen::Vector3d& axis;
  } axes[] = {{"u_axis", plane->frame.u_axis}, {"v_axis", plane->frame.v_axis}};
  for (const auto& a : axes) {
    const std::string axis_field = JsonFields::Join(field, a.key);
    if (std::abs(a.axis.norm() - 1.0) > kMapUnitTolerance) {
      f.Fail(axis_field, "not of unit length (norm " +
                             std::to_string(a.axis.norm()) + ")");
    }
    if (std::abs(a.axis.dot(n)) > kMapUnitTolerance) {
      f.Fail(axis_field, "not in the plane (dot with normal " +
                             std::to_string(a.axis.dot(n)) + ")");
    }
  }
  if (std::abs(plane->frame.u_axis.dot(plane->frame.v_axis)) >
      kMapUnitTolerance) {
    f.Fail(JsonFields::Join(field, "v_axis"), "not orthogonal to u_axis");
  }
  const double distance = plane->plane.SignedDistance(plane->frame.origin);
  if (std::abs(distance) >
      kMapOnPlaneToleranceM * std::max(1.0, std::abs(plane->plane.offset))) {
    f.Fail(JsonFields::Join(field, "origin"),
           "not on the plane (distance " + std::to_string(distance) + " m)");
  }
}

Polygon2d ReadPolygon(const JsonFields& f, const json& p,
                      const std::string& field, const char* key = "polygon") {
  const std::string polygon_field = JsonFields::Join(field, key);
  const json& polygon = f.Array(p, field, key);
  if (polygon.size() < 3) {
    f.Fail(polygon_field, "needs at least 3 vertices, got " +
                              std::to_string(polygon.size()));
  }
  Polygon2d vertices;
  for (size_t i = 0; i < polygon.size(); ++i) {
    vertices.push_back(
        f.Vector<2>(polygon[i], JsonFields::Index(polygon_field, i)));
  }
  return vertices;
}

std::vector<PlaneFeature> ReadPlaneFeatures(const JsonFields& f, const json& p,
                                            const std::string& field) {
  const std::string features_field = JsonFields::Join(field, "features");
  const json& features = f.Array(p, field, "features");
  std::vector<PlaneFeature> out;
  for (size_t i = 0; i < features.size(); ++i) {
    const std::string ff = JsonFields::Index(features_field, i);
    if (!features[i].is_object()) f.Fail(ff, "expected an object");
    PlaneFeature feature;
    feature.id = f.Integer(features[i], ff, "id");
    feature.x_in_world = f.Vector<3>(features[i], ff, "xyz");
    feature.texture_px = f.Vector<2>(features[i], ff, "texture_px");
    out.push_back(feature);
  }
  return out;
}

// The texture (BGRA): a plain file name inside the map directory.
cv::Mat ReadPlaneTexture(const JsonFields& f, const json& p,
                         const std::string& field, const fs::path& dir) {
  const std::string texture_field = JsonFields::Join(field, "texture");
  const std::string texture_name = f.String(p, field, "texture");
  const fs::path texture_path(texture_name);
  if (texture_name.empty() || texture_path.has_parent_path() ||
      texture_path.is_absolute() || texture_name == "." ||
      texture_name == "..") {
    f.Fail(texture_field, "'" + texture_name +
                              "' is not a plain file name in the map folder");
  }
  const fs::path full = dir / texture_path;
  std::error_code ec;
  if (!fs::is_regular_file(full, ec)) {
    f.Fail(texture_field, "texture file " + full.string() + " is missing");
  }
  cv::Mat texture = ToBgra(ReadImageFile(full, cv::IMREAD_UNCHANGED));
  if (texture.empty()) {
    throw InputError(full.string() +
                     ": texture must be an 8-bit grey, BGR or BGRA image");
  }
  return texture;
}

TexturedPlane ReadPlane(const JsonFields& f, const json& p,
                        const std::string& field, const fs::path& dir) {
  if (!p.is_object()) f.Fail(field, "expected an object");
  TexturedPlane plane;
  plane.id = f.Int(p, field, "id");
  // -1 means "no plane" in points.ply.
  if (plane.id < 0) f.Fail(JsonFields::Join(field, "id"), "must be >= 0");
  plane.plane.normal = f.Vector<3>(p, field, "normal");
  const double normal_norm = plane.plane.normal.norm();
  if (std::abs(normal_norm - 1.0) > kMapUnitTolerance) {
    f.Fail(JsonFields::Join(field, "normal"),
           "not of unit length (norm " + std::to_string(normal_norm) + ")");
  }
  plane.plane.offset = f.Number(p, field, "offset");
  ReadPlaneFrame(f, p, field, &plane);
  plane.pixels_per_meter = f.Number(p, field, "pixels_per_meter");
  if (plane.pixels_per_meter <= 0) {
    f.Fail(JsonFields::Join(field, "pixels_per_meter"), "must be positive");
  }
  plane.polygon = ReadPolygon(f, p, field);
  // Optional: written only for grown planes (older maps have none).
  if (p.contains("landmark_polygon")) {
    plane.landmark_polygon = ReadPolygon(f, p, field, "landmark_polygon");
  }
  plane.features = ReadPlaneFeatures(f, p, field);
  plane.texture = ReadPlaneTexture(f, p, field, dir);
  return plane;
}

}  // namespace

std::string PlaneTextureFileName(int plane_id) {
  return "plane_" + std::to_string(plane_id) + ".png";
}

std::string FormatMapJson(const Map& map) {
  OrderedJson root;
  root["format"] = kMapFormatName;
  root["version"] = kMapFormatVersion;
  auto camera_json = [](const Camera& c) {
    OrderedJson j{{"width", c.width},
                  {"height", c.height},
                  {"fx", c.fx},
                  {"fy", c.fy},
                  {"cx", c.cx},
                  {"cy", c.cy},
                  {"distortion", c.distortion}};
    if (c.model != LensModel::kPlumbBob) j["model"] = LensModelName(c.model);
    return j;
  };
  root["camera"] = camera_json(map.camera);
  if (map.given_camera) root["given_camera"] = camera_json(*map.given_camera);
  OrderedJson planes = OrderedJson::array();
  for (const TexturedPlane& p : map.planes) {
    OrderedJson polygon = OrderedJson::array();
    for (const auto& st : p.polygon) polygon.push_back(VectorJson(st));
    OrderedJson landmark_polygon = OrderedJson::array();
    for (const auto& st : p.landmark_polygon) {
      landmark_polygon.push_back(VectorJson(st));
    }
    OrderedJson features = OrderedJson::array();
    for (const PlaneFeature& feature : p.features) {
      features.push_back({{"id", feature.id},
                          {"xyz", VectorJson(feature.x_in_world)},
                          {"texture_px", VectorJson(feature.texture_px)}});
    }
    planes.push_back({{"id", p.id},
                      {"normal", VectorJson(p.plane.normal)},
                      {"offset", p.plane.offset},
                      {"texture", PlaneTextureFileName(p.id)},
                      {"origin", VectorJson(p.frame.origin)},
                      {"u_axis", VectorJson(p.frame.u_axis)},
                      {"v_axis", VectorJson(p.frame.v_axis)},
                      {"pixels_per_meter", p.pixels_per_meter},
                      {"polygon", std::move(polygon)}});
    if (!p.landmark_polygon.empty()) {
      planes.back()["landmark_polygon"] = std::move(landmark_polygon);
    }
    planes.back()["features"] = std::move(features);
  }
  root["planes"] = std::move(planes);
  root["num_landmarks"] = map.landmarks.size();
  root["num_frames"] = map.trajectory.size();
  return root.dump(1) + "\n";
}

void WriteMap(const fs::path& dir, const Map& map) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) {
    throw OutputError(dir.string() + ": map directory does not exist");
  }
  std::set<int> ids;
  std::vector<cv::Mat> textures;
  for (const TexturedPlane& p : map.planes) {
    const std::string what = dir.string() + ": plane " + std::to_string(p.id);
    if (!ids.insert(p.id).second) throw OutputError(what + ": duplicate id");
    if (p.polygon.size() < 3) {
      throw OutputError(what + ": polygon has fewer than 3 vertices");
    }
    if (!(p.pixels_per_meter > 0)) {
      throw OutputError(what + ": pixels_per_meter must be positive");
    }
    textures.push_back(ToBgra(p.texture));
    if (textures.back().empty()) {
      throw OutputError(what + ": texture is empty or not 8-bit 1/3/4 channel");
    }
  }
  for (size_t i = 0; i < map.planes.size(); ++i) {
    std::vector<uchar> png;
    if (!cv::imencode(".png", textures[i], png)) {
      throw OutputError(dir.string() + ": cannot encode texture of plane " +
                        std::to_string(map.planes[i].id));
    }
    WriteFileAtomic(dir / PlaneTextureFileName(map.planes[i].id),
                    std::string(png.begin(), png.end()));
  }
  WriteLandmarksPly(dir / kMapPointsFile, map.landmarks);
  WriteTumTrajectory(dir / kMapTrajectoryFile, map.trajectory,
                     "monomap map trajectory (refined)");
  WriteMapGlb(dir / kMapGlbFile, map);
  // map.json last: its presence marks a complete map.
  WriteFileAtomic(dir / kMapJsonFile, FormatMapJson(map));
}

Map ReadMap(const fs::path& dir) {
  const fs::path json_path = dir / kMapJsonFile;
  // Anything else at the path (a FIFO, a symlink loop) is named by the
  // reader below.
  if (!PathExists(json_path)) {
    throw InputError(json_path.string() + ": missing (not a monomap map " +
                     "directory?)");
  }
  const JsonFields f(json_path.string());
  json root;
  try {
    root = json::parse(ReadFileToString(json_path));
  } catch (const json::exception& e) {  // syntax, number overflow, ...
    throw InputError(json_path.string() + ": invalid JSON: " + e.what());
  }
  if (!root.is_object()) {
    throw InputError(json_path.string() + ": top level is not a JSON object");
  }
  const std::string format = f.String(root, "", "format");
  if (format != kMapFormatName) {
    f.Fail("format", "expected '" + std::string(kMapFormatName) + "', got '" +
                         format + "'");
  }
  const int64_t version = f.Integer(root, "", "version");
  if (version != kMapFormatVersion) {
    f.Fail("version", "unsupported version " + std::to_string(version) +
                          " (this build reads version " +
                          std::to_string(kMapFormatVersion) + ")");
  }
  Map map;
  map.camera = ReadCamera(f, root, "camera");
  if (root.contains("given_camera")) {
    map.given_camera = ReadCamera(f, root, "given_camera");
  }
  const json& planes = f.Array(root, "", "planes");
  std::set<int> ids;
  for (size_t i = 0; i < planes.size(); ++i) {
    const std::string field = JsonFields::Index("planes", i);
    map.planes.push_back(ReadPlane(f, planes[i], field, dir));
    if (!ids.insert(map.planes.back().id).second) {
      f.Fail(JsonFields::Join(field, "id"),
             "duplicate plane id " + std::to_string(map.planes.back().id));
    }
  }
  const int64_t num_landmarks = f.Integer(root, "", "num_landmarks");
  const int64_t num_frames = f.Integer(root, "", "num_frames");
  if (num_landmarks < 0) f.Fail("num_landmarks", "negative");
  if (num_frames < 0) f.Fail("num_frames", "negative");

  const fs::path trajectory_path = dir / kMapTrajectoryFile;
  if (!PathExists(trajectory_path)) {
    throw InputError(trajectory_path.string() + ": missing");
  }
  // An empty trajectory file (no poses) is valid only for num_frames = 0.
  if (num_frames > 0) map.trajectory = ReadTumTrajectory(trajectory_path);
  if (static_cast<int64_t>(map.trajectory.size()) != num_frames) {
    throw InputError(trajectory_path.string() + ": has " +
                     std::to_string(map.trajectory.size()) +
                     " poses but map.json num_frames is " +
                     std::to_string(num_frames));
  }

  const fs::path points_path = dir / kMapPointsFile;
  if (PathExists(points_path)) {
    map.landmarks = ReadLandmarksPly(points_path);
    if (static_cast<int64_t>(map.landmarks.size()) != num_landmarks) {
      throw InputError(points_path.string() + ": has " +
                       std::to_string(map.landmarks.size()) +
                       " points but map.json num_landmarks is " +
                       std::to_string(num_landmarks));
    }
  }
  return map;
}

}  // namespace monomap
