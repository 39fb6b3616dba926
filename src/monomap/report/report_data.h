// The report data: everything the HTML page (html_page.h) shows, as one
// JSON document, gathered from a map directory and optionally the dataset
// it was built from and localization runs in it. Missing or corrupt input
// files do not stop it: each becomes a ReportProblem (named on the page)
// and the rest of the report is still gathered.
//
// JSON layout (all positions in the map's world frame, metres):
//   title, provenance {command_line, version, commit, generated_utc,
//     inputs {map, dataset, localization[]}}
//   problems [{file, message}]
//   map_files [{name, path, link, bytes, status ok|missing|corrupt, message}]
//   summary {frames, landmarks, planes, tracks}
//   glb_base64                      map.glb, for the 3D view
//   planes [{id, width, height, pixels_per_meter, coverage,
//            points, png_base64}]
//   points {xyz [x0,y0,z0,x1,...], plane [id0, id1, ...]}
//   trajectories [{name, t [], xyz []}]   map, odometry, ground truth
//   errors {alignment, series [{name, t [], error_m []}]}
//   features {frames [{frame, timestamp, width, height, jpeg_base64,
//             tracks [[u0,v0,u1,v1,...]]}]}
//   localization [{name, sources [], t [], xyz [], groundtruth_xyz [],
//                  error_m [], steps [...], particles {steps [t...],
//                  xyz [[...]]}}]
//   extra                           figures a caller adds (the demo's)
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "monomap/map/map.h"

namespace monomap {

// One input file that could not be read (or is missing).
struct ReportProblem {
  std::string file;
  std::string message;
};

// A localization run: the estimate and, where known, the ground truth and
// the particle sets, all in the map frame.
struct LocalizationRunData {
  std::string name;
  std::vector<std::string> sources;  // files it was read from
  std::vector<TimedPose> trajectory;
  std::vector<TimedPose> groundtruth;
  // Camera positions of (a subset of) the particles after each step.
  std::vector<std::vector<Eigen::Vector3d>> particles;
  // Per-step figures (localize's --report JSON: its "steps" array and
  // totals), or null.
  nlohmann::json report;
};

struct ReportInputs {
  std::filesystem::path map_dir;
  // The dataset the map was built from (empty: none): ground truth,
  // odometry and the images of the tracked-feature overlays.
  std::filesystem::path dataset_dir;
  std::vector<LocalizationRunData> localization;
  // Page title (empty: "monomap report: <map dir name>").
  std::string title;
  // The command that made the report, for the provenance section.
  std::string command_line;
  // Figures a caller adds; shown as tables (e.g. the demo's evaluation).
  nlohmann::json extra;
  // Problems the caller met gathering the inputs (e.g. a localization
  // run's files); the page names them with the others.
  std::vector<ReportProblem> problems;
};

struct ReportOptions {
  // Landmarks drawn in the 3D view (a fixed stride keeps it deterministic).
  int max_points = 20000;
  // Width (px) textures are reduced to on the page (map.glb keeps all).
  int max_texture_width = 512;
  // Frames with tracked-feature overlays, and their width on the page.
  int overlay_frames = 3;
  int overlay_width = 640;
  // Frames of history drawn per track in the overlays.
  int overlay_tail = 10;
  // Particles kept per step and steps kept per run (stride) in the page.
  int max_particles_per_step = 400;
  int max_particle_steps = 300;

  void Check() const;
};

struct ReportData {
  nlohmann::json json;
  std::vector<ReportProblem> problems;
};

// Gathers the report. Never throws on bad input files (they become
// problems); throws OptionsError on bad options.
ReportData BuildReportData(const ReportInputs& inputs,
                           const ReportOptions& options = {});

// The command line of this process (from /proc/self/cmdline), or "".
std::string CurrentCommandLine();

// Standard base64 (RFC 4648, with padding).
std::string Base64Encode(const std::string& bytes);

}  // namespace monomap
