// The end-to-end demo: simulate a world, build its map, evaluate the map
// against the simulator's exact ground truth, localize a second traversal
// in it, and write all figures as JSON (DIR/report.json). The HTML page
// is the report module's (exe/demo_command.cc writes DIR/report.html from
// the map, the dataset and this report).
//
// Output directory layout:
//   DIR/dataset/      the simulated dataset (with structure/ = true planes)
//   DIR/map/          the built map (see io/map_format.h)
//   DIR/localization_dataset/  a second traversal, localized in the map
//   DIR/report.json  every figure of the evaluation
#pragma once

#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "monomap/eval/structure_accuracy.h"
#include "monomap/eval/trajectory_metrics.h"
#include "monomap/pipelines/demo_localization.h"
#include "monomap/pipelines/mapping_pipeline.h"

namespace monomap {

struct DemoOptions {
  // Where the dataset, the map and the report go (created if missing).
  std::filesystem::path output_dir = "out/demo";
  // Simulated world, one of WorldNames().
  std::string world = "hallway";
  // Frames to simulate and map: 200 at 640x480 keeps the whole demo well
  // under 2 minutes on 2 cores.
  int num_frames = 200;
  // Image size of the simulated camera.
  int width = 640;
  int height = 480;
  // Seed of the simulation (textures, odometry errors, noise).
  uint64_t seed = 1;
  // The calibration the map is built from and the second traversal is
  // localized with; empty: the simulator's true lens. A wrong one shows
  // what lens self-calibration recovers (mapping.bundle_adjustment.
  // intrinsics). Its size must be the simulated images'.
  std::optional<Camera> given_camera;
  // Mapping options (show_progress follows the field below).
  MappingOptions mapping;
  // How the map is compared with the simulator's true planes.
  StructureAccuracyOptions structure;
  // Frame offset of the relative pose error (30 frames = 1 s at 30 Hz).
  int rpe_delta_frames = 30;
  // The second traversal localized in the map (MCL and MCC from a global
  // initialisation) and the map's texture fidelity on it.
  DemoLocalizationOptions localization;
  // Draw progress bars and stage messages on stderr.
  bool show_progress = true;

  void Check() const;
};

struct DemoReport {
  std::filesystem::path report_json;
  std::filesystem::path dataset_dir;
  std::filesystem::path map_dir;

  int frames = 0;
  int tracks = 0;
  int landmarks = 0;

  // The map against the true planes (points, plane matches, precision and
  // recall), after the first-pose alignment of the odometry.
  StructureAccuracy structure;

  // First-pose aligned ATE and RPE against groundtruth.txt.
  TrajectoryErrors ate_refined;
  TrajectoryErrors ate_odometry;
  TrajectoryErrors rpe_refined;
  TrajectoryErrors rpe_odometry;

  // The localization part (empty runs if disabled).
  DemoLocalization localization;

  // Mapping report (counts and per-stage timings).
  nlohmann::json mapping;
  double simulate_seconds = 0.0;
  double mapping_seconds = 0.0;
  double evaluation_seconds = 0.0;
  double total_seconds = 0.0;

  // Every figure above (what report.json holds).
  nlohmann::json ToJson() const;
};

// Runs the demo. Throws OptionsError on bad options, and whatever the
// simulator, the pipeline or the writers throw (InputError, StageError,
// OutputError).
DemoReport RunDemo(const DemoOptions& options);

}  // namespace monomap
