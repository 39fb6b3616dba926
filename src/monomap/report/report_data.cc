#include "monomap/report/report_data.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>

#include "monomap/eval/trajectory_metrics.h"
#include "monomap/io/dataset.h"
#include "monomap/io/feature_table.h"
#include "monomap/io/map_format.h"
#include "monomap/io/ply.h"
#include "monomap/io/trajectory_io.h"
#include "monomap/util/error.h"
#include "monomap/util/file.h"

#ifndef MONOMAP_VERSION
#define MONOMAP_VERSION "unknown"
#endif
#ifndef MONOMAP_COMMIT
#define MONOMAP_COMMIT "unknown"
#endif

namespace monomap {

void ReportOptions::Check() const {
  CheckOption(max_points >= 1, "report.max_points", "must be >= 1");
  CheckOption(max_texture_width >= 1, "report.max_texture_width",
              "must be >= 1");
  CheckOption(overlay_frames >= 0, "report.overlay_frames", "must be >= 0");
  CheckOption(overlay_width >= 1, "report.overlay_width", "must be >= 1");
  CheckOption(overlay_tail >= 1, "report.overlay_tail", "must be >= 1");
  CheckOption(max_particles_per_step >= 1, "report.max_particles_per_step",
              "must be >= 1");
  CheckOption(max_particle_steps >= 1, "report.max_particle_steps",
              "must be >= 1");
}

std::string Base64Encode(const std::string& bytes) {
  static const char* kAlphabet =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (size_t i = 0; i < bytes.size(); i += 3) {
    const size_t n = std::min<size_t>(3, bytes.size() - i);
    uint32_t v = 0;
    for (size_t k = 0; k < 3; ++k) {
      v = (v << 8) | (k < n ? static_cast<unsigned char>(bytes[i + k]) : 0u);
    }
    for (size_t k = 0; k < 4; ++k) {
      out += k <= n ? kAlphabet[(v >> (18 - 6 * k)) & 63] : '=';
    }
  }
  return out;
}

std::string CurrentCommandLine() {
  std::ifstream in("/proc/self/cmdline", std::ios::binary);
  std::string raw((std::istreambuf_iterator<char>(in)),
                  std::istreambuf_iterator<char>());
  std::string out;
  for (const char c : raw) out += c == '\0' ? ' ' : c;
  while (!out.empty() && out.back() == ' ') out.pop_back();
  return out;
}

namespace {

// Millimetre (or millisecond) resolution keeps the page small.
double Round3(double v) { return std::round(v * 1000.0) / 1000.0; }

void AppendXyz(const Eigen::Vector3d& x, nlohmann::json* flat) {
  for (int k = 0; k < 3; ++k) flat->push_back(Round3(x[k]));
}

nlohmann::json TrajectoryJson(const std::string& name,
                              const std::vector<TimedPose>& poses) {
  nlohmann::json t = nlohmann::json::array(), xyz = nlohmann::json::array();
  for (const TimedPose& p : poses) {
    t.push_back(Round3(p.timestamp));
    AppendXyz(p.world_from_cam.translation, &xyz);
  }
  return {{"name", name}, {"t", t}, {"xyz", xyz}};
}

std::vector<TimedPose> Transformed(const Rigid3d& to_from,
                                   const std::vector<TimedPose>& poses) {
  std::vector<TimedPose> out = poses;
  for (TimedPose& p : out) p.world_from_cam = to_from * p.world_from_cam;
  return out;
}

// Position error of `estimate` against `groundtruth` (same frame) at each
// estimate timestamp that has a ground-truth pose.
nlohmann::json ErrorSeries(const std::string& name,
                           const std::vector<TimedPose>& estimate,
                           const std::vector<TimedPose>& groundtruth) {
  nlohmann::json t = nlohmann::json::array(), e = nlohmann::json::array();
  for (const auto& [i, g] : AssociateByTimestamp(estimate, groundtruth)) {
    t.push_back(Round3(estimate[i].timestamp));
    e.push_back(std::round(1e5 * (estimate[i].world_from_cam.translation -
                                  groundtruth[g].world_from_cam.translation)
                                     .norm()) /
                1e5);
  }
  return {{"name", name}, {"t", t}, {"error_m", e}};
}

std::string EncodeImage(const cv::Mat& image, const char* ext) {
  std::vector<uchar> bytes;
  const std::vector<int> params =
      std::string(ext) == ".jpg"
          ? std::vector<int>{cv::IMWRITE_JPEG_QUALITY, 85}
          : std::vector<int>{};
  if (!cv::imencode(ext, image, bytes, params)) return "";
  return Base64Encode(std::string(bytes.begin(), bytes.end()));
}

// Collects problems and the status of each map file.
class MapFiles {
 public:
  MapFiles(const std::filesystem::path& dir, std::vector<ReportProblem>* p)
      : dir_(dir), problems_(p) {}

  // Runs `read` on dir/name; records the file as ok, missing or corrupt.
  // Returns whether it succeeded.
  template <typename F>
  bool Read(const std::string& name, bool required, F&& read) {
    const std::filesystem::path path = dir_ / name;
    nlohmann::json f = {{"name", name}, {"path", path.string()}};
    std::error_code ec;
    const bool exists = std::filesystem::is_regular_file(path, ec);
    f["bytes"] = exists ? std::filesystem::file_size(path, ec) : 0;
    bool ok = false;
    if (!exists) {
      f["status"] = required ? "missing" : "absent (optional)";
      if (required) Problem(path.string(), "missing", &f);
    } else {
      try {
        read(path);
        f["status"] = "ok";
        ok = true;
      } catch (const Error& e) {
        f["status"] = "corrupt";
        Problem(path.string(), e.what(), &f);
      } catch (const std::exception& e) {
        f["status"] = "corrupt";
        Problem(path.string(), e.what(), &f);
      }
    }
    files_.push_back(f);
    return ok;
  }

  nlohmann::json Json() const { return files_; }

 private:
  void Problem(const std::string& file, const std::string& message,
               nlohmann::json* f) {
    (*f)["message"] = message;
    problems_->push_back({file, message});
  }

  std::filesystem::path dir_;
  std::vector<ReportProblem>* problems_;
  nlohmann::json files_ = nlohmann::json::array();
};

// What could be read of a map directory.
struct MapPieces {
  std::optional<Map> map;  // map.json with its textures
  std::vector<Landmark> landmarks;
  std::vector<TimedPose> trajectory;
  std::vector<Track> tracks;
  std::string glb;
};

void CheckGlb(const std::string& bytes) {
  // The 12-byte header: magic "glTF", version 2, total length.
  if (bytes.size() < 12 || bytes.compare(0, 4, "glTF") != 0) {
    throw InputError("not a glTF binary (no glTF header)");
  }
  uint32_t length = 0;
  for (int k = 3; k >= 0; --k) {
    length = (length << 8) | static_cast<unsigned char>(bytes[8 + k]);
  }
  if (length != bytes.size()) {
    throw InputError("truncated: header says " + std::to_string(length) +
                     " bytes, file has " + std::to_string(bytes.size()));
  }
}

MapPieces ReadMapPieces(const std::filesystem::path& dir, MapFiles* files) {
  MapPieces m;
  files->Read(kMapTrajectoryFile, true,
              [&](const auto& p) { m.trajectory = ReadTumTrajectory(p); });
  files->Read(kMapPointsFile, true,
              [&](const auto& p) { m.landmarks = ReadLandmarksPly(p); });
  files->Read(kMapGlbFile, true, [&](const auto& p) {
    std::string bytes = ReadFileToString(p);
    CheckGlb(bytes);
    m.glb = std::move(bytes);
  });
  files->Read("features.csv", false,
              [&](const auto& p) { m.tracks = ReadFeatureTable(p); });
  // map.json with the plane textures; ReadMap also re-reads the
  // trajectory and points, whose own problems are already recorded.
  files->Read(kMapJsonFile, true, [&](const auto&) {
    try {
      m.map = ReadMap(dir);
    } catch (const InputError& e) {
      const std::string what = e.what();
      if (what.find(kMapTrajectoryFile) != std::string::npos ||
          what.find(kMapPointsFile) != std::string::npos) {
        return;  // named under that file; map.json itself may be fine
      }
      throw;
    }
  });
  return m;
}

// Fraction of the plane's polygon (in texels) that has texture (alpha > 0).
double TextureCoverage(const TexturedPlane& p) {
  if (p.texture.empty() || p.polygon.size() < 3) return 0.0;
  cv::Mat mask = cv::Mat::zeros(p.texture.size(), CV_8UC1);
  std::vector<cv::Point> poly;
  for (const Eigen::Vector2d& st : p.polygon) {
    const Eigen::Vector2d px = st * p.pixels_per_meter;
    poly.emplace_back(cvRound(px.x()), cvRound(px.y()));
  }
  cv::fillPoly(mask, std::vector<std::vector<cv::Point>>{poly}, 255);
  const int inside = cv::countNonZero(mask);
  if (inside == 0) return 0.0;
  cv::Mat textured = mask.clone();
  if (p.texture.channels() == 4) {
    cv::Mat alpha;
    cv::extractChannel(p.texture, alpha, 3);
    textured = mask & (alpha > 0);
  }
  return static_cast<double>(cv::countNonZero(textured)) / inside;
}

nlohmann::json PlanesJson(const Map& map,
                          const std::vector<Landmark>& landmarks,
                          const ReportOptions& options) {
  nlohmann::json planes = nlohmann::json::array();
  for (const TexturedPlane& p : map.planes) {
    const auto points =
        std::count_if(landmarks.begin(), landmarks.end(),
                      [&](const Landmark& l) { return l.plane_id == p.id; });
    cv::Mat tex = p.texture;
    if (!tex.empty() && tex.cols > options.max_texture_width) {
      const double s =
          static_cast<double>(options.max_texture_width) / tex.cols;
      cv::resize(tex, tex,
                 cv::Size(options.max_texture_width,
                          std::max(1, cvRound(tex.rows * s))),
                 0, 0, cv::INTER_AREA);
    }
    planes.push_back(
        {{"id", p.id},
         {"width", p.texture.cols},
         {"height", p.texture.rows},
         {"pixels_per_meter", Round3(p.pixels_per_meter)},
         {"coverage", Round3(TextureCoverage(p))},
         {"points", points},
         {"png_base64", tex.empty() ? "" : EncodeImage(tex, ".png")}});
  }
  return planes;
}

nlohmann::json PointsJson(const std::vector<Landmark>& landmarks,
                          const ReportOptions& options) {
  nlohmann::json xyz = nlohmann::json::array(), plane = nlohmann::json::array();
  const size_t stride = std::max<size_t>(
      1, (landmarks.size() + options.max_points - 1) / options.max_points);
  for (size_t i = 0; i < landmarks.size(); i += stride) {
    AppendXyz(landmarks[i].x_in_world, &xyz);
    plane.push_back(landmarks[i].plane_id);
  }
  return {{"xyz", xyz}, {"plane", plane}, {"total", landmarks.size()}};
}

// Index of the dataset frame with this timestamp, or -1.
int FrameAt(const Dataset& d, double t) {
  for (size_t i = 0; i < d.frames.size(); ++i) {
    if (std::abs(d.frames[i].timestamp - t) < 1e-3) return static_cast<int>(i);
  }
  return -1;
}

// Frames of the dataset with the tracks seen there (feature table frame
// indices count the frames the map was built from, i.e. its trajectory).
nlohmann::json FeaturesJson(const Dataset& d, const MapPieces& m,
                            const ReportOptions& options,
                            std::vector<ReportProblem>* problems) {
  nlohmann::json frames = nlohmann::json::array();
  const int n = static_cast<int>(m.trajectory.size());
  if (m.tracks.empty() || n == 0) return {{"frames", frames}};
  for (int k = 1; k <= options.overlay_frames; ++k) {
    const int f = k * n / (options.overlay_frames + 1);
    const int image_index = FrameAt(d, m.trajectory[f].timestamp);
    if (image_index < 0) continue;
    cv::Mat image;
    try {
      image = d.LoadImage(image_index, /*color=*/true);
    } catch (const Error& e) {
      problems->push_back(
          {d.frames[image_index].image_path.string(), e.what()});
      continue;
    }
    const double s =
        std::min(1.0, static_cast<double>(options.overlay_width) / image.cols);
    if (s < 1.0) cv::resize(image, image, cv::Size(), s, s, cv::INTER_AREA);
    nlohmann::json tracks = nlohmann::json::array();
    for (const Track& t : m.tracks) {
      nlohmann::json line = nlohmann::json::array();
      bool seen_now = false;
      for (const Observation& o : t.observations) {
        if (o.frame < f - options.overlay_tail || o.frame > f) continue;
        line.push_back(std::round(o.px.x() * s * 10) / 10);
        line.push_back(std::round(o.px.y() * s * 10) / 10);
        seen_now = seen_now || o.frame == f;
      }
      if (seen_now) tracks.push_back(line);
    }
    frames.push_back({{"frame", f},
                      {"timestamp", Round3(m.trajectory[f].timestamp)},
                      {"width", image.cols},
                      {"height", image.rows},
                      {"tail", options.overlay_tail},
                      {"jpeg_base64", EncodeImage(image, ".jpg")},
                      {"tracks", tracks}});
  }
  return {{"frames", frames}};
}

// Trajectories and their errors against the dataset's ground truth (if
// any), in the map frame: the ground truth is brought into it by aligning
// the map's first pose with the first ground-truth pose.
void AddDatasetFigures(const Dataset& d, const MapPieces& m,
                       nlohmann::json* j) {
  std::vector<TimedPose> odometry, groundtruth;
  for (const DatasetFrame& f : d.frames) {
    odometry.push_back({f.timestamp, f.odometry_world_from_cam});
    if (f.groundtruth_world_from_cam) {
      groundtruth.push_back({f.timestamp, *f.groundtruth_world_from_cam});
    }
  }
  nlohmann::json& trajectories = (*j)["trajectories"];
  if (groundtruth.empty() || m.trajectory.empty() ||
      AssociateByTimestamp(m.trajectory, groundtruth).empty()) {
    trajectories.push_back(TrajectoryJson("odometry", odometry));
    return;
  }
  const Rigid3d map_from_world =
      AlignTrajectories(m.trajectory, groundtruth, Alignment::kFirstPose)
          .rigid.Inverse();
  const std::vector<TimedPose> gt_in_map =
      Transformed(map_from_world, groundtruth);
  // Odometry aligned the same way (its first pose on the ground truth's).
  const Rigid3d gt_from_odometry =
      AlignTrajectories(odometry, groundtruth, Alignment::kFirstPose).rigid;
  const std::vector<TimedPose> odometry_in_map =
      Transformed(map_from_world * gt_from_odometry, odometry);
  trajectories.push_back(TrajectoryJson("odometry", odometry_in_map));
  trajectories.push_back(TrajectoryJson("ground truth", gt_in_map));
  (*j)["errors"] = {{"alignment", "first pose"},
                    {"series",
                     {ErrorSeries("map (refined)", m.trajectory, gt_in_map),
                      ErrorSeries("odometry", odometry_in_map, gt_in_map)}}};
}

nlohmann::json LocalizationJson(const LocalizationRunData& run,
                                const ReportOptions& options) {
  nlohmann::json j = TrajectoryJson(run.name, run.trajectory);
  j["sources"] = run.sources;
  j["report"] = run.report;
  if (!run.groundtruth.empty()) {
    j["groundtruth"] = TrajectoryJson("ground truth", run.groundtruth);
    j["error"] = ErrorSeries(run.name, run.trajectory, run.groundtruth);
  }
  nlohmann::json steps = nlohmann::json::array(), xyz = nlohmann::json::array();
  const size_t n = run.particles.size();
  const size_t stride = std::max<size_t>(
      1, (n + options.max_particle_steps - 1) / options.max_particle_steps);
  for (size_t s = 0; s < n; s += stride) {
    nlohmann::json flat = nlohmann::json::array();
    const size_t count = std::min<size_t>(run.particles[s].size(),
                                          options.max_particles_per_step);
    for (size_t i = 0; i < count; ++i) AppendXyz(run.particles[s][i], &flat);
    steps.push_back(s);
    xyz.push_back(flat);
  }
  j["particles"] = {{"steps", steps}, {"xyz", xyz}};
  return j;
}

std::string UtcNow() {
  const std::time_t now =
      std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  char text[32];
  std::tm tm{};
  gmtime_r(&now, &tm);
  std::strftime(text, sizeof(text), "%Y-%m-%d %H:%M:%S UTC", &tm);
  return text;
}

nlohmann::json ProvenanceJson(const ReportInputs& in) {
  nlohmann::json runs = nlohmann::json::array();
  for (const LocalizationRunData& r : in.localization) {
    runs.push_back({{"name", r.name}, {"sources", r.sources}});
  }
  return {{"command_line", in.command_line},
          {"version", MONOMAP_VERSION},
          {"commit", MONOMAP_COMMIT},
          {"generated_utc", UtcNow()},
          {"inputs",
           {{"map", in.map_dir.string()},
            {"dataset", in.dataset_dir.string()},
            {"localization", runs}}}};
}

}  // namespace

ReportData BuildReportData(const ReportInputs& in,
                           const ReportOptions& options) {
  options.Check();
  ReportData out;
  out.problems = in.problems;
  nlohmann::json& j = out.json;
  j["title"] = in.title.empty()
                   ? "monomap report: " + in.map_dir.filename().string()
                   : in.title;
  j["provenance"] = ProvenanceJson(in);
  MapFiles files(in.map_dir, &out.problems);
  const MapPieces m = ReadMapPieces(in.map_dir, &files);
  j["map_files"] = files.Json();
  j["glb_base64"] = Base64Encode(m.glb);
  j["planes"] = m.map ? PlanesJson(*m.map, m.landmarks, options)
                      : nlohmann::json::array();
  j["points"] = PointsJson(m.landmarks, options);
  j["trajectories"] = nlohmann::json::array();
  if (!m.trajectory.empty()) {
    j["trajectories"].push_back(TrajectoryJson("map (refined)", m.trajectory));
  }
  j["errors"] = {{"series", nlohmann::json::array()}};
  j["features"] = {{"frames", nlohmann::json::array()}};
  if (!in.dataset_dir.empty()) {
    try {
      const Dataset d = LoadDataset(in.dataset_dir);
      AddDatasetFigures(d, m, &j);
      j["features"] = FeaturesJson(d, m, options, &out.problems);
    } catch (const Error& e) {
      out.problems.push_back({in.dataset_dir.string(), e.what()});
    }
  }
  j["localization"] = nlohmann::json::array();
  for (const LocalizationRunData& run : in.localization) {
    j["localization"].push_back(LocalizationJson(run, options));
  }
  j["summary"] = {{"frames", m.trajectory.size()},
                  {"landmarks", m.landmarks.size()},
                  {"planes", m.map ? m.map->planes.size() : 0},
                  {"tracks", m.tracks.size()}};
  j["extra"] = in.extra;
  j["problems"] = nlohmann::json::array();
  for (const ReportProblem& p : out.problems) {
    j["problems"].push_back({{"file", p.file}, {"message", p.message}});
  }
  return out;
}

}  // namespace monomap
