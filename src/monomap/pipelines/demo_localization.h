// The localization part of the demo: a second traversal of the simulated
// world (same textures, other odometry errors and image noise, a start and
// a lateral offset), localized in the demo's map from a global
// initialisation with MCL and with MCC under the same particle budget, and
// the map's texture fidelity on that traversal's held-out ground-truth
// poses.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "monomap/eval/localization_accuracy.h"
#include "monomap/eval/render_fidelity.h"
#include "monomap/geometry/rigid3.h"
#include "monomap/localization/localizer.h"
#include "monomap/map/map.h"
#include "monomap/pipelines/localization_pipeline.h"
#include "monomap/sim/simulate.h"

namespace monomap {

struct DemoLocalizationOptions {
  // Run the localization part at all.
  bool enabled = true;
  // Frames of the second traversal.
  int num_frames = 100;
  // It starts this far (m) into the mapped path and this far (m) beside it.
  double start_offset_m = 0.5;
  double lateral_offset_m = 0.15;
  // Its run seed is the world seed plus this (other odometry errors and
  // image noise than the mapping run).
  uint64_t run_seed_offset = 1000;
  // The filters' seed is the world seed plus this: other values show the
  // filter's own scatter on one map and traversal.
  uint64_t filter_seed_offset = 0;
  // Particle budget of both methods (initial count and KLD maximum). A
  // corridor seen at 80x60 has look-alike stretches metres apart; 1000
  // particles over the whole hallway often lock onto one of them, 3000
  // cover it densely enough (docs/design-notes.md, "particle budget").
  int particles = 3000;
  // The traversal's calibration as the localizer is told it; empty: the
  // simulator's true lens. The map's refined lens replaces it when the map
  // was built from this very calibration (LensForLocalization).
  std::optional<Camera> given_camera;
  // Particles kept per step for the report (a random subset keeps the
  // page small).
  int plotted_particles = 400;
  // Every n-th frame of the traversal is rendered for texture fidelity.
  int fidelity_stride = 5;
  // What counts as localized (translation and rotation thresholds).
  LocalizationAccuracyOptions accuracy;
  RenderFidelityOptions fidelity;

  void Check() const;
};

// One method on the traversal.
struct DemoLocalizationRun {
  std::string name;  // "MCL" or "MCC"
  LocalizationReport report;
  LocalizationAccuracy accuracy;
  // The estimate per step (map frame).
  std::vector<TimedPose> trajectory;
  // Camera positions of a subset of the particles after each step.
  std::vector<std::vector<Eigen::Vector3d>> particles;

  nlohmann::json ToJson() const;
};

struct DemoLocalization {
  std::filesystem::path dataset_dir;
  int frames = 0;
  // Ground truth of the traversal in the map frame.
  std::vector<TimedPose> groundtruth;
  RenderFidelity fidelity;
  std::vector<DemoLocalizationRun> runs;
  double simulate_seconds = 0.0;
  double seconds = 0.0;  // the whole part

  nlohmann::json ToJson() const;
};

// Simulates the traversal into `dataset_dir` with `mapping_sim`'s world
// and seed, and localizes it in `map`. map_from_world takes the
// simulator's world frame into the map's (the first-pose alignment of the
// mapping run's odometry). Throws what the simulator, the dataset loader
// and the localizer throw.
DemoLocalization RunDemoLocalization(const Map& map,
                                     const SimulationOptions& mapping_sim,
                                     const Rigid3d& map_from_world,
                                     const DemoLocalizationOptions& options,
                                     const std::filesystem::path& dataset_dir);

}  // namespace monomap
