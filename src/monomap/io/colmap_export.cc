#include "monomap/io/colmap_export.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <map>
#include <unordered_map>
#include <unordered_set>

#include "monomap/util/error.h"
#include "monomap/util/file.h"

namespace monomap {

namespace {

namespace fs = std::filesystem;

constexpr const char* kCamerasFile = "cameras.txt";
constexpr const char* kImagesFile = "images.txt";
constexpr const char* kPointsFile = "points3D.txt";

// COLMAP's image origin is the top-left corner of the top-left pixel.
constexpr double kColmapPixelShift = 0.5;

// Shortest representation that parses back to the same double.
void AppendNumber(double value, std::string* out) {
  char buf[64];
  const auto result = std::to_chars(buf, buf + sizeof(buf), value);
  out->append(buf, result.ptr);
}

void AppendNumbers(std::initializer_list<double> values, std::string* out) {
  for (double v : values) {
    out->push_back(' ');
    AppendNumber(v, out);
  }
}

// Parameters of the supported models, in COLMAP's order.
int NumParams(const std::string& model) {
  static const std::map<std::string, int> kParams = {
      {"SIMPLE_PINHOLE", 3}, {"PINHOLE", 4}, {"SIMPLE_RADIAL", 4},
      {"RADIAL", 5},         {"OPENCV", 8},  {"FULL_OPENCV", 12},
      {"OPENCV_FISHEYE", 8}};
  const auto it = kParams.find(model);
  return it == kParams.end() ? -1 : it->second;
}

// A text file split into lines, with the reader's position and errors that
// name file and line.
class LineReader {
 public:
  explicit LineReader(const fs::path& path)
      : path_(path), text_(ReadFileToString(path)) {}

  // Next line that is neither blank nor a comment; false at the end.
  bool NextDataLine(std::string* line) {
    while (NextRawLine(line)) {
      const size_t first = line->find_first_not_of(" \t\r");
      if (first != std::string::npos && (*line)[first] != '#') return true;
    }
    return false;
  }
  // The next line as it is (possibly blank); false at the end.
  bool NextRawLine(std::string* line) {
    if (pos_ >= text_.size()) return false;
    size_t end = text_.find('\n', pos_);
    if (end == std::string::npos) end = text_.size();
    *line = text_.substr(pos_, end - pos_);
    pos_ = end + 1;
    ++number_;
    return true;
  }
  [[noreturn]] void Fail(const std::string& what) const {
    throw InputError(path_.string(), number_, what);
  }
  double Double(const std::string& token, const char* field) const {
    double v = 0;
    if (!ParseDouble(token, &v)) {
      Fail(std::string(field) + " '" + token + "' is not a finite number");
    }
    return v;
  }
  int64_t Int(const std::string& token, const char* field) const {
    int64_t v = 0;
    const auto r =
        std::from_chars(token.data(), token.data() + token.size(), v);
    if (r.ec != std::errc() || r.ptr != token.data() + token.size()) {
      Fail(std::string(field) + " '" + token + "' is not an integer");
    }
    return v;
  }

 private:
  fs::path path_;
  std::string text_;
  size_t pos_ = 0;
  int number_ = 0;
};

std::vector<ColmapModel::Camera> ReadCameras(const fs::path& path) {
  LineReader in(path);
  std::vector<ColmapModel::Camera> cameras;
  std::string line;
  while (in.NextDataLine(&line)) {
    const std::vector<std::string> t = SplitWhitespace(line);
    if (t.size() < 4) in.Fail("expected CAMERA_ID MODEL WIDTH HEIGHT PARAMS");
    ColmapModel::Camera c;
    c.id = static_cast<int>(in.Int(t[0], "CAMERA_ID"));
    c.model = t[1];
    c.width = static_cast<int>(in.Int(t[2], "WIDTH"));
    c.height = static_cast<int>(in.Int(t[3], "HEIGHT"));
    const int n = NumParams(c.model);
    if (n >= 0 && static_cast<int>(t.size()) != 4 + n) {
      in.Fail("model " + c.model + " needs " + std::to_string(n) +
              " parameters, got " + std::to_string(t.size() - 4));
    }
    for (size_t k = 4; k < t.size(); ++k) {
      c.params.push_back(in.Double(t[k], "PARAMS"));
    }
    cameras.push_back(c);
  }
  return cameras;
}

std::vector<ColmapModel::Image> ReadImages(const fs::path& path) {
  LineReader in(path);
  std::vector<ColmapModel::Image> images;
  std::string line;
  while (in.NextDataLine(&line)) {
    const std::vector<std::string> t = SplitWhitespace(line);
    if (t.size() != 10) {
      in.Fail("expected IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME");
    }
    ColmapModel::Image im;
    im.id = static_cast<int>(in.Int(t[0], "IMAGE_ID"));
    double v[7];
    for (int k = 0; k < 7; ++k) v[k] = in.Double(t[1 + k], "pose");
    const Eigen::Quaterniond q(v[0], v[1], v[2], v[3]);
    if (std::abs(q.norm() - 1.0) > 1e-6) in.Fail("quaternion not unit");
    im.cam_from_world_rotation = q.normalized();
    im.cam_from_world_translation = Eigen::Vector3d(v[4], v[5], v[6]);
    im.camera_id = static_cast<int>(in.Int(t[8], "CAMERA_ID"));
    im.name = t[9];
    if (!in.NextRawLine(&line)) in.Fail("missing the POINTS2D line");
    const std::vector<std::string> p = SplitWhitespace(line);
    if (p.size() % 3 != 0) in.Fail("POINTS2D is not a list of X Y POINT3D_ID");
    for (size_t k = 0; k < p.size(); k += 3) {
      ColmapModel::Point2D pt;
      pt.xy = {in.Double(p[k], "X"), in.Double(p[k + 1], "Y")};
      pt.point3d_id = in.Int(p[k + 2], "POINT3D_ID");
      im.points2d.push_back(pt);
    }
    images.push_back(std::move(im));
  }
  return images;
}

std::vector<ColmapModel::Point3D> ReadPoints(const fs::path& path) {
  LineReader in(path);
  std::vector<ColmapModel::Point3D> points;
  std::string line;
  while (in.NextDataLine(&line)) {
    const std::vector<std::string> t = SplitWhitespace(line);
    if (t.size() < 8 || (t.size() - 8) % 2 != 0) {
      in.Fail("expected POINT3D_ID X Y Z R G B ERROR (IMAGE_ID POINT2D_IDX)*");
    }
    ColmapModel::Point3D pt;
    pt.id = in.Int(t[0], "POINT3D_ID");
    pt.xyz = {in.Double(t[1], "X"), in.Double(t[2], "Y"), in.Double(t[3], "Z")};
    for (int k = 0; k < 3; ++k) {
      pt.rgb[k] = static_cast<int>(in.Int(t[4 + k], "RGB"));
      if (pt.rgb[k] < 0 || pt.rgb[k] > 255) in.Fail("colour outside 0..255");
    }
    pt.error = in.Double(t[7], "ERROR");
    for (size_t k = 8; k < t.size(); k += 2) {
      pt.track.push_back({static_cast<int>(in.Int(t[k], "IMAGE_ID")),
                          static_cast<int>(in.Int(t[k + 1], "POINT2D_IDX"))});
    }
    points.push_back(std::move(pt));
  }
  return points;
}

// Cross-checks ids: images name known cameras, track elements point at
// existing 2D points that name the same 3D point.
void CheckConsistency(const fs::path& dir, const ColmapModel& model) {
  std::unordered_set<int> camera_ids;
  for (const auto& c : model.cameras) camera_ids.insert(c.id);
  std::unordered_map<int, const ColmapModel::Image*> images;
  for (const auto& im : model.images) {
    if (!camera_ids.count(im.camera_id)) {
      throw InputError((dir / kImagesFile).string(),
                       "image " + std::to_string(im.id),
                       "unknown CAMERA_ID " + std::to_string(im.camera_id));
    }
    images[im.id] = &im;
  }
  for (const auto& p : model.points) {
    for (const auto& e : p.track) {
      const auto it = images.find(e.image_id);
      const bool ok =
          it != images.end() && e.point2d_idx >= 0 &&
          e.point2d_idx < static_cast<int>(it->second->points2d.size()) &&
          it->second->points2d[e.point2d_idx].point3d_id == p.id;
      if (!ok) {
        throw InputError((dir / kPointsFile).string(),
                         "point " + std::to_string(p.id),
                         "track element (" + std::to_string(e.image_id) + ", " +
                             std::to_string(e.point2d_idx) +
                             ") does not name a 2D point of this point");
      }
    }
  }
}

std::string FrameName(int frame) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "frame_%06d.png", frame);
  return buf;
}

// The 3D point of a landmark; its track's observations become 2D points of
// `images`. Counts go to `report`, the sum of reprojection errors to
// `error_sum`.
ColmapModel::Point3D MakePoint(const Landmark& l, const Track* track,
                               const Camera& camera,
                               const std::vector<Rigid3d>& cam_from_world,
                               std::vector<ColmapModel::Image>* images,
                               ColmapExportReport* report, double* error_sum) {
  ColmapModel::Point3D p;
  p.id = l.id;
  p.xyz = l.x_in_world;
  for (int k = 0; k < 3; ++k) {
    p.rgb[k] =
        static_cast<int>(std::lround(std::clamp(l.color[k], 0.f, 255.f)));
  }
  if (track == nullptr) return p;
  const int num_frames = static_cast<int>(cam_from_world.size());
  double point_error = 0;
  for (const Observation& o : track->observations) {
    const Eigen::Vector3d x_in_cam =
        o.frame >= 0 && o.frame < num_frames
            ? cam_from_world[o.frame] * l.x_in_world
            : Eigen::Vector3d::Zero();
    if (!(x_in_cam.z() > 0)) {
      ++report->num_dropped_observations;
      continue;
    }
    point_error += (camera.ImageFromCam(x_in_cam) - o.px).norm();
    ColmapModel::Image& im = (*images)[o.frame];
    p.track.push_back({im.id, static_cast<int>(im.points2d.size())});
    im.points2d.push_back(
        {o.px + Eigen::Vector2d::Constant(kColmapPixelShift), l.id});
  }
  if (!p.track.empty()) {
    p.error = point_error / p.track.size();
    *error_sum += point_error;
    report->num_observations += static_cast<int>(p.track.size());
    ++report->num_points_with_track;
  }
  return p;
}

std::string FormatCameras(const ColmapModel& model) {
  std::string cameras =
      "# Camera list with one line of data per camera:\n"
      "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
      "# Number of cameras: " +
      std::to_string(model.cameras.size()) + "\n";
  for (const auto& c : model.cameras) {
    cameras += std::to_string(c.id) + " " + c.model + " " +
               std::to_string(c.width) + " " + std::to_string(c.height);
    for (double v : c.params) AppendNumbers({v}, &cameras);
    cameras += "\n";
  }
  return cameras;
}

std::string FormatImages(const ColmapModel& model) {
  std::string images =
      "# Image list with two lines of data per image:\n"
      "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n"
      "#   POINTS2D[] as (X, Y, POINT3D_ID)\n"
      "# Number of images: " +
      std::to_string(model.images.size()) + "\n";
  for (const auto& im : model.images) {
    const Eigen::Quaterniond& q = im.cam_from_world_rotation;
    const Eigen::Vector3d& t = im.cam_from_world_translation;
    images += std::to_string(im.id);
    AppendNumbers({q.w(), q.x(), q.y(), q.z(), t.x(), t.y(), t.z()}, &images);
    images += " " + std::to_string(im.camera_id) + " " + im.name + "\n";
    for (size_t k = 0; k < im.points2d.size(); ++k) {
      const auto& p = im.points2d[k];
      if (k > 0) images += " ";
      AppendNumber(p.xy.x(), &images);
      AppendNumbers({p.xy.y()}, &images);
      images += " " + std::to_string(p.point3d_id);
    }
    images += "\n";
  }
  return images;
}

std::string FormatPoints(const ColmapModel& model) {
  std::string points =
      "# 3D point list with one line of data per point:\n"
      "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as "
      "(IMAGE_ID, POINT2D_IDX)\n"
      "# Number of points: " +
      std::to_string(model.points.size()) + "\n";
  for (const auto& p : model.points) {
    points += std::to_string(p.id);
    AppendNumbers({p.xyz.x(), p.xyz.y(), p.xyz.z()}, &points);
    for (int k = 0; k < 3; ++k) points += " " + std::to_string(p.rgb[k]);
    AppendNumbers({p.error}, &points);
    for (const auto& e : p.track) {
      points += " " + std::to_string(e.image_id) + " " +
                std::to_string(e.point2d_idx);
    }
    points += "\n";
  }
  return points;
}

}  // namespace

ColmapModel::Camera ColmapCameraFromCamera(const Camera& camera, int id) {
  ColmapModel::Camera c;
  c.id = id;
  c.width = camera.width;
  c.height = camera.height;
  const double cx = camera.cx + kColmapPixelShift;
  const double cy = camera.cy + kColmapPixelShift;
  const auto& d = camera.distortion;
  if (camera.model == LensModel::kEquidistant) {
    // COLMAP's OPENCV_FISHEYE is the same Kannala-Brandt polynomial.
    c.model = "OPENCV_FISHEYE";
    c.params = {camera.fx, camera.fy, cx, cy, d[0], d[1], d[2], d[3]};
  } else if (!camera.HasDistortion()) {
    c.model = "PINHOLE";
    c.params = {camera.fx, camera.fy, cx, cy};
  } else if (d[4] == 0.0) {
    c.model = "OPENCV";
    c.params = {camera.fx, camera.fy, cx, cy, d[0], d[1], d[2], d[3]};
  } else {
    c.model = "FULL_OPENCV";
    c.params = {camera.fx, camera.fy, cx,   cy,  d[0], d[1],
                d[2],      d[3],      d[4], 0.0, 0.0,  0.0};
  }
  return c;
}

Camera CameraFromColmapCamera(const ColmapModel::Camera& c) {
  const std::string where = "camera " + std::to_string(c.id);
  const int n = NumParams(c.model);
  if (n < 0) {
    throw InputError(kCamerasFile, where,
                     "camera model " + c.model + " is not supported");
  }
  if (static_cast<int>(c.params.size()) != n) {
    throw InputError(kCamerasFile, where, "wrong number of parameters");
  }
  const std::vector<double>& p = c.params;
  Camera camera;
  camera.width = c.width;
  camera.height = c.height;
  const bool simple = c.model.rfind("SIMPLE_", 0) == 0 || c.model == "RADIAL";
  // SIMPLE_* and RADIAL: f cx cy [k1 [k2]]; the others: fx fy cx cy ...
  const int o = simple ? 1 : 2;
  camera.fx = p[0];
  camera.fy = simple ? p[0] : p[1];
  camera.cx = p[o] - kColmapPixelShift;
  camera.cy = p[o + 1] - kColmapPixelShift;
  for (int k = o + 2; k < std::min(n, o + 6); ++k) {
    camera.distortion[k - o - 2] = p[k];
  }
  if (c.model == "OPENCV_FISHEYE") camera.model = LensModel::kEquidistant;
  if (c.model == "FULL_OPENCV") {
    if (p[9] != 0 || p[10] != 0 || p[11] != 0) {
      throw InputError(kCamerasFile, where,
                       "FULL_OPENCV with k4..k6 != 0 (rational model) is not "
                       "supported");
    }
    camera.distortion[4] = p[8];
  }
  return camera;
}

ColmapModel MakeColmapModel(const Map& map, const std::vector<Track>& tracks,
                            const std::vector<std::string>& image_names,
                            ColmapExportReport* report) {
  const int num_frames = static_cast<int>(map.trajectory.size());
  if (!image_names.empty() &&
      static_cast<int>(image_names.size()) != num_frames) {
    throw OutputError("COLMAP export: " + std::to_string(image_names.size()) +
                      " image names for " + std::to_string(num_frames) +
                      " poses");
  }
  ColmapExportReport r;
  ColmapModel model;
  model.cameras.push_back(ColmapCameraFromCamera(map.camera));
  r.camera_model = model.cameras[0].model;
  std::vector<Rigid3d> cam_from_world(num_frames);
  for (int f = 0; f < num_frames; ++f) {
    ColmapModel::Image im;
    im.id = f + 1;
    cam_from_world[f] = map.trajectory[f].world_from_cam.Inverse();
    im.cam_from_world_rotation = cam_from_world[f].rotation;
    im.cam_from_world_translation = cam_from_world[f].translation;
    im.name = image_names.empty() ? FrameName(f) : image_names[f];
    model.images.push_back(std::move(im));
  }
  std::unordered_map<FeatureId, const Track*> track_of;
  for (const Track& t : tracks) track_of[t.id] = &t;
  std::unordered_set<FeatureId> seen;
  double error_sum = 0;
  for (const Landmark& l : map.landmarks) {
    if (!seen.insert(l.id).second || l.id < 0) {
      throw OutputError("COLMAP export: landmark id " + std::to_string(l.id) +
                        " repeated or negative");
    }
    const auto it = track_of.find(l.id);
    model.points.push_back(
        MakePoint(l, it == track_of.end() ? nullptr : it->second, map.camera,
                  cam_from_world, &model.images, &r, &error_sum));
  }
  r.num_images = num_frames;
  r.num_points = static_cast<int>(model.points.size());
  r.mean_reprojection_error_px =
      r.num_observations > 0 ? error_sum / r.num_observations : 0.0;
  if (report) *report = r;
  return model;
}

void WriteColmapText(const fs::path& dir, const ColmapModel& model) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) {
    throw OutputError(dir.string() +
                      ": cannot create directory: " + ec.message());
  }
  WriteFileAtomic(dir / kCamerasFile, FormatCameras(model));
  WriteFileAtomic(dir / kImagesFile, FormatImages(model));
  WriteFileAtomic(dir / kPointsFile, FormatPoints(model));
}

ColmapModel ReadColmapText(const fs::path& dir) {
  ColmapModel model;
  model.cameras = ReadCameras(dir / kCamerasFile);
  model.images = ReadImages(dir / kImagesFile);
  model.points = ReadPoints(dir / kPointsFile);
  CheckConsistency(dir, model);
  return model;
}

}  // namespace monomap
