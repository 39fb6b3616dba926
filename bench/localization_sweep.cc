// Global localization over many seeds: MCL against MCC on simulated worlds.
//
// For each world and seed s: simulate a mapping run of the world (world
// seed s), build its map from the images and odometry only, simulate a
// second traversal of the same world (same textures, run seed
// 1000 + s: other odometry errors and image noise; a lateral offset and a
// start offset inside the mapped stretch) and localize it from a global
// initialisation (planar state) with each configuration: MCL with the
// particle budget, MCC with the same budget, MCC with a quarter of it.
// The budget is the initial count and the KLD-sampling maximum.
//
// With --kidnap-after K the filter instead starts at the true pose and the
// robot is carried off after K updates: the images jump --kidnap-skip
// frames ahead along the traversal while the odometry goes on as if nothing
// happened. The figures are then those of the updates after the kidnapping
// (converged step = updates until the filter has the pose again).
//
// With --track the filter starts at the true pose and nobody kidnaps it:
// every update the relocalization trigger fires is a false alarm. The
// summary gives that share beside the CPU time per update (all threads:
// the cores the filter needs to keep up) and its 95th percentile.
//
// Writes every figure (and the per-step errors and particle counts) to
// --out as JSON and prints markdown summary tables on stdout.
//
//   build-loc/bench/localization_sweep --worlds hallway,room --seeds 20
//       --out /tmp/localization_sweep.json
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "monomap/eval/localization_accuracy.h"
#include "monomap/eval/trajectory_metrics.h"
#include "monomap/io/dataset.h"
#include "monomap/io/map_format.h"
#include "monomap/localization/localizer.h"
#include "monomap/pipelines/localization_pipeline.h"
#include "monomap/pipelines/mapping_pipeline.h"
#include "monomap/sim/simulate.h"
#include "monomap/util/angles.h"
#include "monomap/util/error.h"
#include "monomap/util/file.h"
#include "monomap/util/progress.h"
#include "monomap/util/runtime.h"
#include "monomap/util/stats.h"
#include "sweep_main.h"

namespace monomap {
namespace {

namespace fs = std::filesystem;

struct SweepOptions {
  std::vector<std::string> worlds = {"hallway", "room"};
  int seeds = 20;
  int first_seed = 1;
  // Kidnap mode adds kidnap_skip to both runs, so that the map still
  // covers the whole (longer) localization traversal.
  int map_frames = 200;
  int loc_frames = 120;
  int width = 640;
  int height = 480;
  // MCL's budget; MCC runs with it and with a quarter of it.
  int particles = 1000;
  // Keep the particle count fixed instead of KLD-sampling up to the budget.
  bool fixed_count = false;
  double start_offset_m = 0.5;
  double lateral_offset_m = 0.15;
  // Run seed of the localization traversal: run_seed_base + seed.
  uint64_t run_seed_base = 1000;
  // Threads of the bundle adjustment. More than one is faster but not
  // bit-reproducible (the map then differs in the last digits from run to
  // run, which is enough to flip some global-localization outcomes).
  int ba_threads = 1;
  // Likelihood temperature of the measurement model (<= 0: the
  // localizer's default).
  double sigma = 0.0;
  // MCC: width of the estimate's refinement (0: off; -1: the localizer's
  // default).
  int refine_width = -1;
  // MCC: the refinement stops after a round that moved less than this (px;
  // negative: the localizer's default).
  double refine_converged_px = -1.0;
  // Also run every MCC configuration with the refinement stopping at this
  // (px; negative: not), as a twin named <config>_conv on the same maps
  // and traversals: a default is compared at half the cost of two sweeps.
  double twin_refine_converged_px = -1.0;
  // MCC: least random particles injected per resampling (-1: the
  // localizer's default).
  int mcc_min_injected = -1;
  // MCC: largest rotation a correction may make (degrees; <= 0: the
  // localizer's default).
  double mcc_max_rotation_deg = 0.0;
  // Relocalization trigger (RecoveryOptions::relocalize_*; a negative
  // value: the localizer's default).
  double relocalize_ncc_drop = -1.0;
  double relocalize_fraction = -1.0;
  double relocalize_alpha_slow = -1.0;
  // Kidnapped robot: carried off after this many updates (0: no kidnapping,
  // global initialisation instead) ...
  int kidnap_after = 0;
  // ... this many frames ahead along the traversal.
  int kidnap_skip = 60;
  // Start at the true pose without kidnapping (false-alarm runs).
  bool track = false;
  // Configurations to run (empty: all; names as in the summary, e.g.
  // mcc_3000).
  std::vector<std::string> configs;
  LocalizationAccuracyOptions accuracy;
  std::string out = "localization_sweep.json";
  std::string keep_dir;
};

struct Config {
  std::string name;
  LocalizationMethod method;
  int particles;
  // Overrides SweepOptions::refine_converged_px if >= 0.
  double refine_converged_px = -1.0;
};

struct ConfigRun {
  bool ok = false;  // the run finished (map and localization)
  // Over the whole run, or over the updates after a kidnapping.
  LocalizationAccuracy accuracy;
  // Kidnapping only: the filter had the pose when the robot was carried
  // off (the last update before it within the thresholds).
  bool tracked_before_kidnap = false;
  double mean_step_ms = 0.0;
  double mean_particles = 0.0;
  std::vector<int> particles;  // per step, after the update
  // Updates judged for false alarms (all with --track; those before the
  // kidnapping otherwise) and how many of them relocalized.
  int judged_steps = 0;
  int false_alarms = 0;
  std::vector<double> cpu_ms;  // per step, all threads
};

// Median of the finite values (failed runs report NaN errors); NaN if
// there are none, so that "no value" does not read as 0.
double FiniteMedian(std::vector<double> v) {
  std::erase_if(v, [](double x) { return !std::isfinite(x); });
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  return Median(std::move(v));
}

double Mean(const std::vector<double>& v) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  double s = 0.0;
  for (double x : v) s += x;
  return s / v.size();
}

// The q-quantile (nearest rank) of the finite values; NaN if none.
double Percentile(std::vector<double> v, double q) {
  std::erase_if(v, [](double x) { return !std::isfinite(x); });
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(v.begin(), v.end());
  const size_t k = static_cast<size_t>(std::ceil(q * v.size()));
  return v[std::clamp<size_t>(k, 1, v.size()) - 1];
}

nlohmann::json Number(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json();
}

std::string Fmt(const char* format, double v) {
  if (!std::isfinite(v)) return "-";
  char buf[64];
  std::snprintf(buf, sizeof(buf), format, v);
  return buf;
}

std::vector<TimedPose> GroundTruth(const Dataset& d) {
  std::vector<TimedPose> out;
  for (const DatasetFrame& f : d.frames) {
    if (f.groundtruth_world_from_cam) {
      out.push_back({f.timestamp, *f.groundtruth_world_from_cam});
    }
  }
  return out;
}

// The robot carried off: frames [0, after) then [after + skip, end). The
// odometry of the later frames is moved rigidly so that it continues from
// frame after - 1 with the real step from after + skip - 1 to after + skip:
// nothing in it shows the carrying. Ground truth stays true.
Dataset Kidnap(const Dataset& d, int after, int skip) {
  const int n = static_cast<int>(d.frames.size());
  CheckOption(after >= 1 && after + skip < n, "kidnap",
              "needs 1 <= after and after + skip < the frames simulated");
  Dataset out = d;
  out.frames.assign(d.frames.begin(), d.frames.begin() + after);
  const DatasetFrame& last = d.frames[after - 1];
  const DatasetFrame& before_cut = d.frames[after + skip - 1];
  const Rigid3d fix = last.odometry_world_from_cam *
                      before_cut.odometry_world_from_cam.Inverse();
  // The same rigid move in the plane, for odometry2d.
  double theta = 0.0, c = 1.0, sn = 0.0;
  Eigen::Vector2d shift = Eigen::Vector2d::Zero();
  if (last.odometry_base && before_cut.odometry_base) {
    const Pose2d& a = *last.odometry_base;
    const Pose2d& b = *before_cut.odometry_base;
    theta = a.yaw - b.yaw;
    c = std::cos(theta);
    sn = std::sin(theta);
    shift = Eigen::Vector2d(a.x, a.y) -
            Eigen::Vector2d(c * b.x - sn * b.y, sn * b.x + c * b.y);
  }
  for (int i = after + skip; i < n; ++i) {
    DatasetFrame f = d.frames[i];
    f.odometry_world_from_cam = fix * f.odometry_world_from_cam;
    if (f.odometry_base) {
      const Pose2d p = *f.odometry_base;
      f.odometry_base = Pose2d{c * p.x - sn * p.y + shift.x(),
                               sn * p.x + c * p.y + shift.y(), p.yaw + theta};
    }
    out.frames.push_back(f);
  }
  return out;
}

// Frames the kidnapping adds to both runs (the jump skips them).
int KidnapFrames(const SweepOptions& o) {
  return o.kidnap_after > 0 ? o.kidnap_skip : 0;
}

SimulationOptions SimOptions(const SweepOptions& o, const std::string& world,
                             int seed) {
  SimulationOptions sim;
  sim.world = world;
  sim.seed = static_cast<uint64_t>(seed);
  sim.width = o.width;
  sim.height = o.height;
  sim.show_progress = false;
  return sim;
}

// One world and seed: map, second traversal, every configuration.
nlohmann::json RunSeed(const SweepOptions& o, const std::string& world,
                       int seed, const std::vector<Config>& configs,
                       const fs::path& root, std::vector<ConfigRun>* runs) {
  const std::string tag = world + "_s" + std::to_string(seed);
  const fs::path map_data = root / (tag + "_map_dataset");
  const fs::path map_dir = root / (tag + "_map");
  const fs::path loc_data = root / (tag + "_loc_dataset");
  const bool keep = !o.keep_dir.empty();
  nlohmann::json j;
  j["world"] = world;
  j["seed"] = seed;

  // 1. The mapping run and its map, from images and odometry only.
  Timer timer;
  SimulationOptions sim = SimOptions(o, world, seed);
  sim.num_frames = o.map_frames + KidnapFrames(o);
  const SimulationReport map_sim = Simulate(sim, map_data);
  const Dataset mapping = LoadDataset(map_data);
  const std::vector<TimedPose> mapping_truth = GroundTruth(mapping);
  Dataset blind = mapping;  // the pipeline never sees ground truth
  blind.has_groundtruth = false;
  for (DatasetFrame& f : blind.frames) f.groundtruth_world_from_cam.reset();
  MappingOptions mapping_options;
  mapping_options.show_progress = false;
  mapping_options.bundle_adjustment.num_threads = o.ba_threads;
  const MappingResult built = BuildMap(blind, mapping_options);
  WriteMappingResult(map_dir, built);
  if (!keep) fs::remove_all(map_data);
  // The localizer reads the map as `monomap localize` would.
  const Map map = ReadMap(map_dir);
  if (!keep) fs::remove_all(map_dir);
  const TrajectoryErrors map_ate =
      AbsoluteTrajectoryError(map.trajectory, mapping_truth, Alignment::kNone);
  j["map"] = {{"frames", map_sim.frames},
              {"path_length_m", map_sim.path_length_m},
              {"odometry_drift_m", map_sim.final_drift_m},
              {"landmarks", map.landmarks.size()},
              {"planes", map.planes.size()},
              {"trajectory_error_median_m", map_ate.translation_m.median},
              {"trajectory_error_max_m", map_ate.translation_m.max},
              {"seconds", timer.ElapsedSeconds()}};

  // 2. The localization run: the same world, another traversal.
  timer.Restart();
  const bool kidnap = o.kidnap_after > 0;
  sim.num_frames = o.loc_frames + KidnapFrames(o);
  sim.run_seed = o.run_seed_base + static_cast<uint64_t>(seed);
  sim.path.start_offset_m = o.start_offset_m;
  sim.path.lateral_offset_m = o.lateral_offset_m;
  const SimulationReport loc_sim = Simulate(sim, loc_data);
  const Dataset live =
      kidnap ? Kidnap(LoadDataset(loc_data), o.kidnap_after, o.kidnap_skip)
             : LoadDataset(loc_data);
  const std::vector<TimedPose> live_truth = GroundTruth(live);
  if (kidnap) {
    const Rigid3d& from =
        *live.frames[o.kidnap_after - 1].groundtruth_world_from_cam;
    const Rigid3d& to = *live.frames[o.kidnap_after].groundtruth_world_from_cam;
    j["kidnap"] = {{"after", o.kidnap_after},
                   {"skip", o.kidnap_skip},
                   {"distance_m", (to.translation - from.translation).norm()},
                   {"rotation_deg",
                    RadToDegMulDiv(AngleBetween(from.rotation, to.rotation))}};
  }
  j["localization_run"] = {{"frames", live.frames.size()},
                           {"run_seed", sim.run_seed},
                           {"path_length_m", loc_sim.path_length_m},
                           {"odometry_drift_m", loc_sim.final_drift_m},
                           {"seconds", timer.ElapsedSeconds()}};

  // 3. Every configuration from a global initialisation.
  nlohmann::json results = nlohmann::json::object();
  std::fprintf(stderr,
               "%s seed %d: map %zu landmarks, %zu planes, error "
               "median %.1f cm;",
               world.c_str(), seed, map.landmarks.size(), map.planes.size(),
               100 * map_ate.translation_m.median);
  for (size_t c = 0; c < configs.size(); ++c) {
    LocalizationPipelineOptions po;
    LocalizerOptions& lo = po.localizer;
    lo.method = configs[c].method;
    lo.state = LocalizationState::kPlanar;
    lo.init.kind =
        kidnap || o.track ? LocalizationInit::kPose : LocalizationInit::kGlobal;
    lo.mcl.SetParticleBudget(configs[c].particles);
    lo.mcl.use_kld = !o.fixed_count;
    lo.seed = static_cast<uint64_t>(seed);
    if (o.sigma > 0) lo.mcl.measurement.sigma = o.sigma;
    if (o.refine_width >= 0) {
      SetEstimateRefinementWidth(o.refine_width, "--refine-width", &lo.mcc);
    }
    const double converged_px = configs[c].refine_converged_px >= 0
                                    ? configs[c].refine_converged_px
                                    : o.refine_converged_px;
    if (converged_px >= 0) lo.mcc.refinement.converged_px = converged_px;
    if (o.mcc_min_injected >= 0) {
      lo.recovery.mcc_min_injected = o.mcc_min_injected;
    }
    if (o.mcc_max_rotation_deg > 0) {
      lo.mcc.corrector.max_rotation_deg = o.mcc_max_rotation_deg;
    }
    if (o.relocalize_ncc_drop >= 0) {
      lo.recovery.relocalize_ncc_drop = o.relocalize_ncc_drop;
    }
    if (o.relocalize_fraction >= 0) {
      lo.recovery.relocalize_fraction = o.relocalize_fraction;
    }
    if (o.relocalize_alpha_slow >= 0) {
      lo.recovery.relocalize_alpha_slow = o.relocalize_alpha_slow;
    }
    std::vector<TimedPose> trajectory;
    const LocalizationReport r = LocalizeSequence(map, live, po, &trajectory);
    ConfigRun& run = (*runs)[c];
    run.ok = true;
    if (kidnap) {
      const auto cut = [&](const std::vector<TimedPose>& v, bool before) {
        return before ? std::vector<TimedPose>(v.begin(),
                                               v.begin() + o.kidnap_after)
                      : std::vector<TimedPose>(v.begin() + o.kidnap_after,
                                               v.end());
      };
      run.tracked_before_kidnap =
          EvaluateLocalization(cut(trajectory, true), cut(live_truth, true),
                               o.accuracy)
              .success;
      run.accuracy = EvaluateLocalization(cut(trajectory, false),
                                          cut(live_truth, false), o.accuracy);
    } else {
      run.accuracy = EvaluateLocalization(trajectory, live_truth, o.accuracy);
    }
    run.mean_step_ms = 1e3 * r.mean_step_seconds;
    run.mean_particles = r.mean_particles;
    nlohmann::json steps_particles = nlohmann::json::array(),
                   steps_weighed = nlohmann::json::array(),
                   steps_ms = nlohmann::json::array(),
                   steps_ncc = nlohmann::json::array(),
                   steps_coverage = nlohmann::json::array(),
                   steps_cluster = nlohmann::json::array(),
                   steps_injected = nlohmann::json::array(),
                   steps_relocalizing = nlohmann::json::array(),
                   steps_cpu_ms = nlohmann::json::array();
    for (size_t k = 0; k < r.steps.size(); ++k) {
      const LocalizerStepStats& s = r.steps[k];
      if (!kidnap || static_cast<int>(k) < o.kidnap_after) {
        ++run.judged_steps;
        run.false_alarms += s.relocalizing;
      }
      run.cpu_ms.push_back(1e3 * s.cpu_seconds);
      steps_relocalizing.push_back(s.relocalizing ? 1 : 0);
      steps_cpu_ms.push_back(1e3 * s.cpu_seconds);
      run.particles.push_back(s.particles);
      steps_particles.push_back(s.particles);
      steps_weighed.push_back(s.particles_weighed);
      steps_ms.push_back(1e3 * s.seconds);
      steps_ncc.push_back(s.best_ncc);
      steps_coverage.push_back(s.best_coverage);
      steps_cluster.push_back(s.cluster_weight);
      steps_injected.push_back(s.injected);
    }
    // Camera positions (x, y) and heading of the optical axis per step.
    nlohmann::json est_xy = nlohmann::json::array(),
                   truth_xy = nlohmann::json::array();
    auto planar = [](const Rigid3d& p) {
      const Eigen::Vector3d z = p.rotation * Eigen::Vector3d::UnitZ();
      return nlohmann::json::array(
          {std::round(1e4 * p.translation.x()) / 1e4,
           std::round(1e4 * p.translation.y()) / 1e4,
           std::round(RadToDegMulDiv(1e2 * std::atan2(z.y(), z.x()))) / 1e2});
    };
    for (size_t k = 0; k < trajectory.size() && k < live_truth.size(); ++k) {
      est_xy.push_back(planar(trajectory[k].world_from_cam));
      truth_xy.push_back(planar(live_truth[k].world_from_cam));
    }
    const Rigid3d& est = trajectory.back().world_from_cam;
    const Rigid3d& gt = live_truth.back().world_from_cam;
    results[configs[c].name] = {
        {"method", lo.method == LocalizationMethod::kMcc ? "mcc" : "mcl"},
        {"particles_budget", configs[c].particles},
        {"accuracy", run.accuracy.ToJson(true)},
        {"tracked_before_kidnap", run.tracked_before_kidnap},
        {"seconds", r.seconds},
        {"mean_step_ms", run.mean_step_ms},
        {"mean_particles", run.mean_particles},
        {"mcc_accepted", r.mcc_accepted},
        {"final_estimate_xyz",
         {est.translation.x(), est.translation.y(), est.translation.z()}},
        {"final_truth_xyz",
         {gt.translation.x(), gt.translation.y(), gt.translation.z()}},
        {"estimate_x_y_heading_per_step", est_xy},
        {"truth_x_y_heading_per_step", truth_xy},
        {"particles_per_step", steps_particles},
        {"weighed_per_step", steps_weighed},
        {"ms_per_step", steps_ms},
        {"best_ncc_per_step", steps_ncc},
        {"best_coverage_per_step", steps_coverage},
        {"cluster_weight_per_step", steps_cluster},
        {"injected_per_step", steps_injected},
        {"relocalizing_per_step", steps_relocalizing},
        {"cpu_ms_per_step", steps_cpu_ms},
        {"false_alarms", run.false_alarms},
        {"judged_steps", run.judged_steps}};
    std::fprintf(
        stderr, " %s %s (%s, %.1f cm)", configs[c].name.c_str(),
        run.accuracy.success ? "ok" : "FAIL",
        run.accuracy.converged_step >= 0
            ? ("step " + std::to_string(run.accuracy.converged_step)).c_str()
            : "-",
        100 * run.accuracy.final_translation_error_m);
  }
  std::fprintf(stderr, "\n");
  if (!keep) fs::remove_all(loc_data);
  j["configs"] = results;
  return j;
}

// Mean particle count at these steps (clamped to the run length).
const std::vector<int> kParticleSteps = {0, 1, 2, 5, 10, 25, 50, 100};

nlohmann::json Summarize(const SweepOptions& o, const std::string& world,
                         const std::vector<Config>& configs,
                         const std::vector<std::vector<ConfigRun>>& runs) {
  nlohmann::json summary = nlohmann::json::object();
  std::printf(
      "\n### %s: %d seeds (%d..%d), map %d frames, localization %d "
      "frames, %dx%d\n\n",
      world.c_str(), o.seeds, o.first_seed, o.first_seed + o.seeds - 1,
      o.map_frames + KidnapFrames(o), o.loc_frames + KidnapFrames(o), o.width,
      o.height);
  if (o.kidnap_after > 0) {
    std::printf(
        "Kidnapped after update %d, %d frames ahead; the figures are those "
        "of the updates after it.\n\n",
        o.kidnap_after, o.kidnap_skip);
  }
  std::printf(
      "| method | particles | success | median converged step | "
      "median final error | median mean tracking error (converged "
      "runs) | mean particles | mean ms / update | CPU ms / update: mean, "
      "p95 | false alarms |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|\n");
  std::vector<std::string> over_time;
  for (size_t c = 0; c < configs.size(); ++c) {
    int ok = 0, success = 0, tracked = 0;
    std::vector<double> conv, final_t, final_r, mean_t, mean_r, particles, ms;
    std::vector<double> cpu_ms;
    int judged = 0, alarms = 0;
    std::vector<double> at_step(kParticleSteps.size(), 0.0);
    std::vector<int> at_count(kParticleSteps.size(), 0);
    for (const auto& seed_runs : runs) {
      const ConfigRun& r = seed_runs[c];
      if (!r.ok) continue;
      ++ok;
      tracked += r.tracked_before_kidnap;
      const LocalizationAccuracy& a = r.accuracy;
      if (a.success) {
        ++success;
        conv.push_back(a.converged_step);
        mean_t.push_back(a.mean_translation_error_m);
        mean_r.push_back(a.mean_rotation_error_deg);
      }
      final_t.push_back(a.final_translation_error_m);
      final_r.push_back(a.final_rotation_error_deg);
      particles.push_back(r.mean_particles);
      ms.push_back(r.mean_step_ms);
      cpu_ms.insert(cpu_ms.end(), r.cpu_ms.begin(), r.cpu_ms.end());
      judged += r.judged_steps;
      alarms += r.false_alarms;
      for (size_t k = 0; k < kParticleSteps.size(); ++k) {
        if (kParticleSteps[k] < static_cast<int>(r.particles.size())) {
          at_step[k] += r.particles[kParticleSteps[k]];
          ++at_count[k];
        }
      }
    }
    const int n = static_cast<int>(runs.size());
    nlohmann::json s;
    s["method"] = configs[c].method == LocalizationMethod::kMcc ? "mcc" : "mcl";
    s["particles_budget"] = configs[c].particles;
    s["runs"] = n;
    s["runs_finished"] = ok;
    s["successes"] = success;
    if (o.kidnap_after > 0) s["tracked_before_kidnap"] = tracked;
    s["success_rate"] = n > 0 ? static_cast<double>(success) / n : 0.0;
    s["median_converged_step"] = Number(FiniteMedian(conv));
    s["median_final_translation_error_m"] = Number(FiniteMedian(final_t));
    s["median_final_rotation_error_deg"] = Number(FiniteMedian(final_r));
    s["median_mean_translation_error_m"] = Number(FiniteMedian(mean_t));
    s["median_mean_rotation_error_deg"] = Number(FiniteMedian(mean_r));
    s["mean_particles"] = Number(Mean(particles));
    s["mean_ms_per_update"] = Number(Mean(ms));
    const double cpu_p95 = Percentile(cpu_ms, 0.95);
    s["mean_cpu_ms_per_update"] = Number(Mean(cpu_ms));
    s["p95_cpu_ms_per_update"] = Number(cpu_p95);
    s["false_alarm_steps"] = alarms;
    s["judged_steps"] = judged;
    const double alarm_pct = judged > 0
                                 ? 100.0 * alarms / judged
                                 : std::numeric_limits<double>::quiet_NaN();
    nlohmann::json pt = nlohmann::json::object();
    std::string row = "| " + configs[c].name + " |";
    for (size_t k = 0; k < kParticleSteps.size(); ++k) {
      const double v = at_count[k] ? at_step[k] / at_count[k]
                                   : std::numeric_limits<double>::quiet_NaN();
      pt[std::to_string(kParticleSteps[k])] = Number(v);
      row += " " + Fmt("%.0f", v) + " |";
    }
    s["mean_particles_at_step"] = pt;
    over_time.push_back(row);
    summary[configs[c].name] = s;
    std::printf(
        "| %s | %d | %d/%d%s | %s | %s cm / %s deg | %s cm / %s deg | "
        "%s | %s | %s, %s | %d/%d (%s %%) |\n",
        s["method"].get<std::string>().c_str(), configs[c].particles, success,
        n,
        o.kidnap_after > 0
            ? (" (tracking before: " + std::to_string(tracked) + ")").c_str()
            : "",
        Fmt("%.0f", FiniteMedian(conv)).c_str(),
        Fmt("%.1f", 100 * FiniteMedian(final_t)).c_str(),
        Fmt("%.1f", FiniteMedian(final_r)).c_str(),
        Fmt("%.1f", 100 * FiniteMedian(mean_t)).c_str(),
        Fmt("%.2f", FiniteMedian(mean_r)).c_str(),
        Fmt("%.0f", Mean(particles)).c_str(), Fmt("%.1f", Mean(ms)).c_str(),
        Fmt("%.1f", Mean(cpu_ms)).c_str(), Fmt("%.1f", cpu_p95).c_str(), alarms,
        judged, Fmt("%.1f", alarm_pct).c_str());
  }
  std::printf(
      "\nParticles alive (mean over seeds) after step%s:\n\n| "
      "configuration |",
      o.kidnap_after > 0 ? " (counted from the start of the run)" : "");
  for (int k : kParticleSteps) std::printf(" %d |", k);
  std::printf("\n|---|");
  for (size_t k = 0; k < kParticleSteps.size(); ++k) std::printf("---|");
  std::printf("\n");
  for (const std::string& row : over_time) std::printf("%s\n", row.c_str());
  std::fflush(stdout);
  return summary;
}

// The twins of the MCC configurations (twin_refine_converged_px).
void AddTwins(const SweepOptions& o, std::vector<Config>* configs) {
  if (o.twin_refine_converged_px < 0) return;
  const size_t n = configs->size();
  for (size_t c = 0; c < n; ++c) {
    if ((*configs)[c].method != LocalizationMethod::kMcc) continue;
    Config twin = (*configs)[c];
    twin.name += "_conv";
    twin.refine_converged_px = o.twin_refine_converged_px;
    configs->push_back(twin);
  }
}

int Run(const SweepOptions& o) {
  o.accuracy.Check();
  CheckOption(o.seeds >= 1, "seeds", "must be >= 1");
  CheckOption(o.particles >= 4, "particles", "must be >= 4");
  CheckOption(o.map_frames >= 10 && o.loc_frames >= 2, "frames",
              "map >= 10, localization >= 2");
  std::vector<Config> configs = {{"mcl_" + std::to_string(o.particles),
                                  LocalizationMethod::kMcl, o.particles},
                                 {"mcc_" + std::to_string(o.particles),
                                  LocalizationMethod::kMcc, o.particles},
                                 {"mcc_" + std::to_string(o.particles / 4),
                                  LocalizationMethod::kMcc, o.particles / 4}};
  if (!o.configs.empty()) {
    std::erase_if(configs, [&](const Config& c) {
      return std::find(o.configs.begin(), o.configs.end(), c.name) ==
             o.configs.end();
    });
    CheckOption(!configs.empty(), "configs", "names none of mcl_N, mcc_N");
  }
  AddTwins(o, &configs);
  const fs::path root =
      o.keep_dir.empty()
          ? fs::temp_directory_path() /
                ("monomap_localization_sweep_" + std::to_string(::getpid()))
          : fs::path(o.keep_dir);
  fs::create_directories(root);

  nlohmann::json out;
  out["options"] = {
      {"worlds", o.worlds},
      {"seeds", o.seeds},
      {"first_seed", o.first_seed},
      {"map_frames", o.map_frames},
      {"loc_frames", o.loc_frames},
      {"width", o.width},
      {"height", o.height},
      {"particles", o.particles},
      {"kld", !o.fixed_count},
      {"start_offset_m", o.start_offset_m},
      {"lateral_offset_m", o.lateral_offset_m},
      {"run_seed_base", o.run_seed_base},
      {"ba_threads", o.ba_threads},
      {"mcc_min_injected", o.mcc_min_injected},
      {"sigma", o.sigma},
      {"refine_width", o.refine_width},
      {"refine_converged_px", o.refine_converged_px},
      {"twin_refine_converged_px", o.twin_refine_converged_px},
      {"mcc_max_rotation_deg", o.mcc_max_rotation_deg},
      {"relocalize_ncc_drop", o.relocalize_ncc_drop},
      {"relocalize_fraction", o.relocalize_fraction},
      {"relocalize_alpha_slow", o.relocalize_alpha_slow},
      {"max_translation_error_m", o.accuracy.max_translation_error_m},
      {"max_rotation_error_deg", o.accuracy.max_rotation_error_deg},
      {"state", "planar"},
      {"init", o.kidnap_after > 0 || o.track ? "pose" : "global"},
      {"track", o.track},
      {"kidnap_after", o.kidnap_after},
      {"kidnap_skip", o.kidnap_skip}};
  out["runs"] = nlohmann::json::array();
  out["summary"] = nlohmann::json::object();
  const Timer total;
  for (const std::string& world : o.worlds) {
    std::vector<std::vector<ConfigRun>> runs;
    for (int seed = o.first_seed; seed < o.first_seed + o.seeds; ++seed) {
      runs.emplace_back(configs.size());
      try {
        out["runs"].push_back(
            RunSeed(o, world, seed, configs, root, &runs.back()));
      } catch (const Error& e) {
        // A map that cannot be built (or a run that cannot be localized)
        // counts as a failure of every configuration not yet run.
        std::fprintf(stderr, "\n%s seed %d: error: %s\n", world.c_str(), seed,
                     e.what());
        out["runs"].push_back(
            {{"world", world}, {"seed", seed}, {"error", e.what()}});
      }
      out["seconds"] = total.ElapsedSeconds();
      WriteFileAtomic(o.out, out.dump(1) + "\n");
    }
    out["summary"][world] = Summarize(o, world, configs, runs);
    WriteFileAtomic(o.out, out.dump(1) + "\n");
  }
  if (o.keep_dir.empty()) fs::remove_all(root);
  out["seconds"] = total.ElapsedSeconds();
  WriteFileAtomic(o.out, out.dump(1) + "\n");
  std::printf("\nTotal %.0f s -> %s\n", total.ElapsedSeconds(), o.out.c_str());
  return 0;
}

}  // namespace
}  // namespace monomap

int main(int argc, char** argv) {
  monomap::ConfigureRuntime();
  monomap::SweepOptions o;
  CLI::App app{
      "Global localization sweep: MCL vs MCC over seeds on "
      "simulated worlds"};
  app.add_option("--worlds", o.worlds, "Worlds (comma-separated)")
      ->delimiter(',');
  app.add_option("--seeds", o.seeds, "Number of seeds per world");
  app.add_option("--first-seed", o.first_seed, "First seed");
  app.add_option("--map-frames", o.map_frames,
                 "Frames of the mapping run (kidnap mode: plus the skip)");
  app.add_option("--loc-frames", o.loc_frames,
                 "Frames of the localization run");
  app.add_option("--width", o.width, "Image width");
  app.add_option("--height", o.height, "Image height");
  app.add_option("--particles", o.particles,
                 "MCL's particle budget (MCC: it and a quarter of it)");
  app.add_flag("--fixed-count", o.fixed_count,
               "Fixed particle count (no KLD-sampling)");
  app.add_option("--start-offset", o.start_offset_m,
                 "Start of the localization run along the path (m)");
  app.add_option("--lateral-offset", o.lateral_offset_m,
                 "Lateral offset of the localization run (m, left)");
  app.add_option("--ba-threads", o.ba_threads,
                 "Bundle adjustment threads (1: bit-reproducible maps)");
  app.add_option("--sigma", o.sigma,
                 "Likelihood temperature of the measurement model (0: the "
                 "localizer's default)");
  app.add_option("--refine-width", o.refine_width,
                 "MCC: width of the estimate's refinement (0: off; -1: the "
                 "localizer's default)");
  app.add_option("--refine-converged-px", o.refine_converged_px,
                 "MCC: the refinement stops after a round that moved less "
                 "than this (px; negative: the localizer's default)");
  app.add_option("--twin-refine-converged-px", o.twin_refine_converged_px,
                 "Also run each MCC configuration with the refinement "
                 "stopping at this (px), as <config>_conv (negative: not)");
  app.add_option("--mcc-min-injected", o.mcc_min_injected,
                 "MCC: least random particles injected per resampling "
                 "(-1: the localizer's default)");
  app.add_option("--mcc-max-rotation-deg", o.mcc_max_rotation_deg,
                 "MCC: largest rotation of a correction (degrees; 0: the "
                 "localizer's default)");
  app.add_option("--relocalize-ncc-drop", o.relocalize_ncc_drop,
                 "Relocalization trigger: drop of the best particle's NCC "
                 "(0: off; negative: the localizer's default)");
  app.add_option("--relocalize-fraction", o.relocalize_fraction,
                 "Share of the budget injected while relocalizing "
                 "(negative: the localizer's default)");
  app.add_option("--relocalize-alpha-slow", o.relocalize_alpha_slow,
                 "Weight of the newest update in the slow average "
                 "(negative: the localizer's default)");
  app.add_option("--kidnap-after", o.kidnap_after,
                 "Start at the true pose and carry the robot off after this "
                 "many updates (0: global initialisation instead)");
  app.add_option("--kidnap-skip", o.kidnap_skip,
                 "Frames along the traversal the robot is carried ahead");
  app.add_flag("--track", o.track,
               "Start at the true pose, no kidnapping: relocalizing counts "
               "as a false alarm");
  app.add_option("--configs", o.configs,
                 "Configurations to run (comma-separated, e.g. "
                 "mcc_3000,mcc_750; default all)")
      ->delimiter(',');
  app.add_option("--max-error-m", o.accuracy.max_translation_error_m,
                 "Success threshold on the position error (m)");
  app.add_option("--max-error-deg", o.accuracy.max_rotation_error_deg,
                 "Success threshold on the rotation error (degrees)");
  app.add_option("--out", o.out, "JSON output file");
  app.add_option("--keep-dir", o.keep_dir,
                 "Write datasets and maps here and keep them (default: a "
                 "temporary directory, emptied as the sweep goes)");
  return monomap::ParseAndRunSweep(app, argc, argv, "localization_sweep",
                                   [&] { return monomap::Run(o); });
}
