// monomap export MAP_DIR [--colmap DIR [--images DATASET]]
//                [--nav-grid DIR [--resolution M] [--z-band MIN MAX]]
//                [--glb FILE [--camera-path] [--points] [--y-up]]
// Writes a map in other tools' formats: a COLMAP text model, a ROS
// map_server occupancy grid, a glb with extras. Everything is computed
// before the first file is written, so bad input writes nothing.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <sstream>

#include "monomap/exe/commands.h"
#include "monomap/io/colmap_export.h"
#include "monomap/io/dataset.h"
#include "monomap/io/feature_table.h"
#include "monomap/io/gltf.h"
#include "monomap/io/map_format.h"
#include "monomap/io/nav_grid_export.h"
#include "monomap/util/error.h"

namespace monomap {

namespace {

namespace fs = std::filesystem;

struct ExportArgs {
  std::string map_dir, colmap_dir, images_dataset, nav_grid_dir, glb_path;
  NavGridOptions nav;
  std::vector<double> z_band;
  GlbOptions glb;
};

// The image file of each trajectory pose, relative to the dataset root (as
// COLMAP's --image_path expects), matched by timestamp.
std::vector<std::string> ImageNames(const Map& map, const fs::path& dataset) {
  const Dataset d = LoadDataset(dataset);
  std::vector<std::string> names;
  size_t j = 0;
  for (const TimedPose& pose : map.trajectory) {
    while (j < d.frames.size() &&
           d.frames[j].timestamp < pose.timestamp - 1e-6) {
      ++j;
    }
    if (j == d.frames.size() ||
        std::abs(d.frames[j].timestamp - pose.timestamp) > 1e-6) {
      throw InputError((dataset / "rgb.txt").string(), "timestamp",
                       "no image at the map's pose timestamp " +
                           std::to_string(pose.timestamp));
    }
    names.push_back(
        fs::relative(d.frames[j].image_path, d.root).generic_string());
  }
  return names;
}

// The COLMAP model of the map, with the tracks of its features.csv.
ColmapModel ColmapOfMap(const ExportArgs& a, const Map& map,
                        ColmapExportReport* report) {
  const fs::path features = fs::path(a.map_dir) / "features.csv";
  const std::vector<Track> tracks =
      fs::exists(features) ? ReadFeatureTable(features) : std::vector<Track>();
  if (tracks.empty()) {
    std::fprintf(stderr,
                 "monomap: warning: %s missing or empty: COLMAP "
                 "points get no tracks\n",
                 features.c_str());
  }
  const std::vector<std::string> names =
      a.images_dataset.empty() ? std::vector<std::string>()
                               : ImageNames(map, a.images_dataset);
  return MakeColmapModel(map, tracks, names, report);
}

void RunExport(const ExportArgs& a) {
  if (a.colmap_dir.empty() && a.nav_grid_dir.empty() && a.glb_path.empty()) {
    throw OptionsError(
        "export: nothing to do: give --colmap, --nav-grid "
        "and/or --glb");
  }
  NavGridOptions nav = a.nav;
  if (!a.z_band.empty()) {
    nav.min_z_m = a.z_band[0];
    nav.max_z_m = a.z_band[1];
  }
  nav.Check();
  const Map map = ReadMap(a.map_dir);
  std::optional<ColmapModel> colmap;
  ColmapExportReport colmap_report;
  if (!a.colmap_dir.empty()) {
    colmap = ColmapOfMap(a, map, &colmap_report);
  }
  std::optional<NavGrid> grid;
  NavGridReport grid_report;
  if (!a.nav_grid_dir.empty()) grid = MakeNavGrid(map, nav, &grid_report);

  if (colmap) {
    WriteColmapText(a.colmap_dir, *colmap);
    std::printf(
        "COLMAP model (%s): %d images, %d points (%d with tracks), "
        "%d observations, mean reprojection error %.3f px -> %s\n",
        colmap_report.camera_model.c_str(), colmap_report.num_images,
        colmap_report.num_points, colmap_report.num_points_with_track,
        colmap_report.num_observations,
        colmap_report.mean_reprojection_error_px, a.colmap_dir.c_str());
  }
  if (grid) {
    WriteNavGrid(a.nav_grid_dir, *grid, nav);
    std::printf(
        "navigation grid %d x %d cells of %.3f m: %d free, %d "
        "occupied, %d unknown (%d floor, %d obstacle planes) -> %s\n",
        grid_report.width, grid_report.height, nav.resolution_m,
        grid_report.num_free, grid_report.num_occupied, grid_report.num_unknown,
        grid_report.num_floor_planes, grid_report.num_obstacle_planes,
        a.nav_grid_dir.c_str());
  }
  if (!a.glb_path.empty()) {
    WriteMapGlb(a.glb_path, map, a.glb);
    std::printf("glb -> %s\n", a.glb_path.c_str());
  }
}

}  // namespace

void RegisterExportCommand(CLI::App& app) {
  auto a = std::make_shared<ExportArgs>();
  CLI::App* cmd = app.add_subcommand(
      "export",
      "Write a map as a COLMAP model, a ROS navigation grid or a glb");
  cmd->add_option("map", a->map_dir, "Map directory (from `monomap build`)")
      ->required()
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--colmap", a->colmap_dir,
                  "Write a COLMAP text model (cameras.txt, images.txt, "
                  "points3D.txt) into this directory");
  cmd->add_option("--images", a->images_dataset,
                  "Dataset the map was built from: name COLMAP images by "
                  "its image files (default: frame_NNNNNN.png)");
  cmd->add_option("--nav-grid", a->nav_grid_dir,
                  "Write a ROS map_server occupancy grid (map.pgm, map.yaml) "
                  "into this directory");
  cmd->add_option("--resolution", a->nav.resolution_m,
                  "Navigation grid cell size (m)")
      ->capture_default_str();
  std::ostringstream band;
  band << a->nav.min_z_m << " " << a->nav.max_z_m;
  cmd->add_option("--z-band", a->z_band,
                  "Height band MIN MAX (world z, m) in which planes are "
                  "obstacles")
      ->expected(2)
      ->default_str(band.str());
  cmd->add_option("--margin", a->nav.margin_m,
                  "Unknown border around the planes (m)")
      ->capture_default_str();
  cmd->add_option("--glb", a->glb_path, "Write a glTF binary of the map");
  cmd->add_flag("--camera-path", a->glb.camera_path,
                "glb: add the camera path as a line strip");
  cmd->add_flag("--points", a->glb.points,
                "glb: add the landmarks as coloured points");
  cmd->add_flag("--y-up", a->glb.y_up,
                "glb: convert world z-up to glTF's Y-up convention");
  cmd->callback([a] { RunExport(*a); });
}

}  // namespace monomap
