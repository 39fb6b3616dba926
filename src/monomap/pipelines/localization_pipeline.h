// LocalizationPipeline: a dataset and a map in, a trajectory out. Runs the
// localizer over the dataset's frames with their odometry increments,
// collects its per-update figures and, where the dataset has ground truth,
// the errors (eval/localization_accuracy.h).
#pragma once

#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <vector>

#include "monomap/eval/localization_accuracy.h"
#include "monomap/io/dataset.h"
#include "monomap/localization/localizer.h"
#include "monomap/localization/session.h"
#include "monomap/map/map.h"

namespace monomap {

struct LocalizationPipelineOptions {
  // The filter; its init options choose the start (a pose init without a
  // pose starts at the first frame's odometry pose, never ground truth).
  LocalizerOptions localizer;
  // Frames with a position error below this (m) count in
  // LocalizationReport::fraction_within_10cm.
  double within_m = 0.1;
  // Draw a progress bar on stderr (only when it is a terminal).
  bool show_progress = true;

  void Check() const;
};

// Per-sequence summary of LocalizeSequence.
struct LocalizationReport {
  int frames = 0;
  double seconds = 0.0;
  double mean_step_seconds = 0.0;
  double mean_particles = 0.0;
  int mcc_accepted = 0;
  // The map's refined lens was used instead of the dataset's calibration
  // (LensForLocalization).
  bool map_lens = false;
  // Against groundtruth, when the dataset has it (else 0 and false).
  bool has_errors = false;
  double rmse_translation_m = 0.0;
  double mean_rotation_error_deg = 0.0;
  double final_translation_error_m = 0.0;
  double final_rotation_error_deg = 0.0;
  // Share of frames with translation error below within_m.
  double fraction_within_10cm = 0.0;
  // Mean errors after converging, once one rigid offset between the
  // estimate's and the truth's frame is removed (a map's frame is its
  // odometry's; LocalizationAccuracy); NaN (JSON null) if too few steps.
  double mean_translation_error_rigid_m = 0.0;
  double mean_rotation_error_rigid_deg = 0.0;
  std::vector<LocalizerStepStats> steps;

  // The figures above (errors only with has_errors) and per step:
  // particles, ess, best_ncc, mcc_accepted, merged, injected, relocalizing,
  // particles_weighed, refined, weigh_seconds, mcc_seconds, seconds.
  nlohmann::json ToJson() const;
};

// Runs the filter over the dataset's frames with its odometry increments
// (odometry2d for the planar state, odometry.txt poses for 6-DoF).
// `trajectory` receives the estimates; `particle_sets` (optional) every
// step's particles after the update. Throws InputError if the dataset
// lacks what the state needs.
LocalizationReport LocalizeSequence(
    const Map& map, const Dataset& dataset,
    const LocalizationPipelineOptions& options,
    std::vector<TimedPose>* trajectory,
    std::vector<std::vector<Particle>>* particle_sets = nullptr);

// The lens to localize with, given the live camera's calibration: the
// map's own lens if the map was built from this very calibration and
// bundle adjustment refined it (Map::given_camera equals `live`: the same
// camera, better known now); otherwise `live` (another camera, or an
// explicitly chosen calibration). *from_map (optional) says which.
Camera LensForLocalization(const Map& map, const Camera& live,
                           bool* from_map = nullptr);

// A streaming session over the map in `map_dir` (io/map_format.h), for a
// live robot. `live_camera`: the camera the images come from (its refined
// lens if the map holds one, LensForLocalization); empty: the map's camera.
// Throws InputError if the map does not load.
std::unique_ptr<LocalizationSession> OpenLocalizationSession(
    const std::filesystem::path& map_dir, const SessionOptions& options,
    const std::optional<Camera>& live_camera = {},
    const std::optional<Rigid3d>& base_from_cam = {});

}  // namespace monomap
