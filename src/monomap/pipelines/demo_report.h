// The end-to-end demo: simulate a world, build its map, evaluate the map
// against the simulator's exact ground truth and write a self-contained
// HTML report (DIR/report.html, images embedded, no external resources)
// plus all figures as JSON (DIR/report.json).
//
// Output directory layout:
//   DIR/dataset/      the simulated dataset (with structure/ = true planes)
//   DIR/map/          the built map (see io/map_format.h)
//   DIR/report.html   the report
//   DIR/report.json   every figure of the report
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "monomap/eval/point_accuracy.h"
#include "monomap/eval/trajectory_metrics.h"

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
  // A fitted plane matches a true plane if the normals differ by at most
  // this angle and the offsets by at most max_match_offset_m.
  double max_match_angle_deg = 2.0;
  // See max_match_angle_deg.
  double max_match_offset_m = 0.03;
  // A landmark whose projection falls this close (m) outside a true plane's
  // polygon still counts as on it (points at corners between planes).
  double polygon_margin_m = 0.03;
  // A true plane counts as observed (for recall) if at least this many
  // landmarks lie within observed_distance_m of it.
  int min_observed_landmarks = 30;
  // See min_observed_landmarks.
  double observed_distance_m = 0.05;
  // Frame offset of the relative pose error (30 frames = 1 s at 30 Hz).
  int rpe_delta_frames = 30;
  // Draw progress bars and stage messages on stderr.
  bool show_progress = true;

  void Check() const;
};

// One fitted plane compared with the ground truth.
struct DemoPlaneMatch {
  int fitted_id = 0;
  int inliers = 0;
  // True plane most of its inliers lie on (-1 if none).
  int true_id = -1;
  double normal_error_deg = 0.0;
  double offset_error_m = 0.0;
  // Within max_match_angle_deg and max_match_offset_m.
  bool matched = false;
};

struct DemoReport {
  std::filesystem::path report_html;
  std::filesystem::path report_json;
  std::filesystem::path dataset_dir;
  std::filesystem::path map_dir;

  int frames = 0;
  int tracks = 0;
  int landmarks = 0;
  int true_planes = 0;
  // True planes with enough landmarks on them to be found.
  int observed_true_planes = 0;
  int fitted_planes = 0;

  // Landmark distance to the nearest true plane containing its projection
  // (absolute, and % of the landmark's mean depth). All landmarks, and
  // only those the map put on a plane.
  PointAccuracy point_error_all;
  PointAccuracy point_error_on_planes;
  // Landmarks whose projection lies on no true plane (not evaluated).
  int landmarks_off_structure = 0;

  std::vector<DemoPlaneMatch> plane_matches;
  ErrorStats plane_normal_error_deg;  // over fitted planes with a true plane
  ErrorStats plane_offset_error_m;
  // Matched fitted planes / fitted planes.
  double plane_precision = 0.0;
  // Observed true planes matched by some fitted plane / observed true
  // planes.
  double plane_recall = 0.0;

  // First-pose aligned ATE and RPE against groundtruth.txt.
  TrajectoryErrors ate_refined;
  TrajectoryErrors ate_odometry;
  TrajectoryErrors rpe_refined;
  TrajectoryErrors rpe_odometry;

  // Mapping report (counts and per-stage timings).
  nlohmann::json mapping;
  double simulate_seconds = 0.0;
  double mapping_seconds = 0.0;
  double evaluation_seconds = 0.0;
  double report_seconds = 0.0;
  double total_seconds = 0.0;

  // Every figure above (what report.json holds).
  nlohmann::json ToJson() const;
};

// Runs the demo. Throws OptionsError on bad options, and whatever the
// simulator, the pipeline or the writers throw (InputError, StageError,
// OutputError).
DemoReport RunDemo(const DemoOptions& options);

}  // namespace monomap
