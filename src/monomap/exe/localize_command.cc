// monomap localize MAP_DIR DATASET --method mcl|mcc [--particles N]
//   [--init global|pose [--init-pose POSE]] [--state planar|6dof] -o TRAJ.txt
//   [--report R.json]
//
// The options bind to the fields of a default-constructed LocalizerOptions,
// so `--help` shows the library's defaults.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include "monomap/exe/cli_parse.h"
#include "monomap/exe/commands.h"
#include "monomap/io/dataset.h"
#include "monomap/io/map_format.h"
#include "monomap/io/trajectory_io.h"
#include "monomap/pipelines/localization_pipeline.h"
#include "monomap/report/html_page.h"
#include "monomap/report/localization_run.h"
#include "monomap/util/error.h"
#include "monomap/util/file.h"

namespace monomap {

namespace {

struct LocalizeArgs {
  std::string map_dir, dataset, output, report, particles_out, camera_yaml;
  std::string html;
  std::string init_pose;
  std::string method = "mcl", init = "pose", state = "planar";
  // WxH strings, parsed into `options` after parsing (empty: the default).
  std::string mcc_size, measure_size;
  // -1: the camera's width (up to 1024); 0: no refinement.
  int refine_width = -1;
  int first_frame = 0, num_frames = -1;
  LocalizerOptions options;
};

std::string SizeString(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

void AddFilterOptions(CLI::App* cmd, LocalizeArgs* a) {
  LocalizerOptions& o = a->options;
  cmd->add_option("--particles", o.mcl.num_particles,
                  "Particle budget (initial count and KLD maximum)")
      ->check(CLI::Range(10, 1000000))
      ->capture_default_str();
  cmd->add_option("--mcc-size", a->mcc_size,
                  "WxH of the renders MCC tracks against")
      ->default_str(SizeString(o.mcc.corrector.width, o.mcc.corrector.height));
  cmd->add_option("--mcc-top-k", o.mcc.top_k,
                  "Heaviest particles MCC corrects per update")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--refine-width", a->refine_width,
                  "MCC: refine each estimate once more against a render "
                  "this wide (the camera's width if smaller; 0: off). Pays "
                  "with a refitted lens, costs 3-5x the update "
                  "(docs/benchmarks.md)")
      ->check(CLI::Range(0, 100000))
      ->default_str(std::to_string(EstimateRefinementWidth(o.mcc)));
  cmd->add_option("--refine-converged-px", o.mcc.refinement.converged_px,
                  "MCC, with --refine-width: stop the estimate's refinement "
                  "after a round that moved its inliers less than this (px; "
                  "0: never). 0.5 saves about a quarter of the refinement "
                  "(docs/benchmarks.md)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--relocalize-ncc-drop", o.recovery.relocalize_ncc_drop,
                  "Inject particles over the area when the best particle's "
                  "NCC drops this far below its long-term average (0: never)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--measure-size", a->measure_size,
                  "WxH of the renders the weights compare")
      ->default_str(
          SizeString(o.mcl.measurement.width, o.mcl.measurement.height));
}

void AddOutputOptions(CLI::App* cmd, LocalizeArgs* a) {
  cmd->add_option("--report", a->report, "Per-step figures as JSON");
  cmd->add_option(
      "--particles-out", a->particles_out,
      "Write the particle sets per step (CSV: step, camera position, "
      "orientation quaternion, log weight)");
  cmd->add_option("--html", a->html,
                  "Also write an HTML report of the run in the map (3D view "
                  "with the particles, errors if the dataset has ground "
                  "truth)");
}

// The parsed strings and flags applied to a copy of the bound options.
LocalizerOptions ResolveOptions(const LocalizeArgs& a) {
  LocalizerOptions options = a.options;
  options.method = ParseLocalizationMethod(a.method);
  options.init.kind = ParseLocalizationInit(a.init);
  options.state = ParseLocalizationState(a.state);
  if (!a.init_pose.empty()) {
    if (options.init.kind != LocalizationInit::kPose) {
      throw OptionsError("--init-pose needs --init pose");
    }
    options.init.pose = ParsePose(a.init_pose, "--init-pose");
  }
  options.mcl.SetParticleBudget(options.mcl.num_particles);
  if (!a.mcc_size.empty()) {
    ParseImageSize(a.mcc_size, "--mcc-size", &options.mcc.corrector.width,
                   &options.mcc.corrector.height);
  }
  if (!a.measure_size.empty()) {
    ParseImageSize(a.measure_size, "--measure-size",
                   &options.mcl.measurement.width,
                   &options.mcl.measurement.height);
  }
  if (a.refine_width >= 0) {
    SetEstimateRefinementWidth(a.refine_width, "--refine-width",
                               &options.mcc);
  }
  return options;
}

// Camera position and orientation (world_from_cam, TUM order) of every
// particle, for plotting the sets.
void WriteParticleSets(const std::string& path,
                       const std::vector<std::vector<Particle>>& sets) {
  std::string csv = "step,x,y,z,qx,qy,qz,qw,log_weight\n";
  char line[240];
  for (size_t s = 0; s < sets.size(); ++s) {
    for (const auto& p : sets[s]) {
      const auto& t = p.world_from_cam.translation;
      const auto& q = p.world_from_cam.rotation;
      std::snprintf(line, sizeof(line),
                    "%zu,%.5f,%.5f,%.5f,%.7f,%.7f,%.7f,%.7f,%.4f\n", s, t.x(),
                    t.y(), t.z(), q.x(), q.y(), q.z(), q.w(), p.log_weight);
      csv += line;
    }
  }
  WriteFileAtomic(path, csv);
}

// The run as `monomap report --localization` would read it back.
void WriteHtml(const LocalizeArgs& a, const Dataset& dataset,
               const std::vector<TimedPose>& trajectory,
               const std::vector<std::vector<Particle>>& sets,
               const LocalizationReport& r) {
  ReportInputs in;
  in.map_dir = a.map_dir;
  in.command_line = CurrentCommandLine();
  LocalizationRunData run;
  run.name = a.method;
  run.sources = {a.output};
  run.trajectory = trajectory;
  for (const DatasetFrame& f : dataset.frames) {
    if (f.groundtruth_world_from_cam) {
      run.groundtruth.push_back({f.timestamp, *f.groundtruth_world_from_cam});
    }
  }
  run.particles =
      ParticlePositions(sets, ReportOptions().max_particles_per_step);
  run.report = r.ToJson();
  in.localization.push_back(std::move(run));
  ThrowIfProblems(WriteReport(in, a.html), a.html);
}

void PrintSummary(const LocalizationReport& r, const std::string& output) {
  std::fprintf(stderr, "monomap: localized %d frames in %.1f s", r.frames,
               r.seconds);
  if (r.has_errors) {
    std::fprintf(stderr, ", rmse %.4f m, final %.4f m / %.3f deg",
                 r.rmse_translation_m, r.final_translation_error_m,
                 r.final_rotation_error_deg);
    if (std::isfinite(r.mean_rotation_error_rigid_deg)) {
      std::fprintf(stderr, ", one rigid offset removed %.4f m / %.3f deg",
                   r.mean_translation_error_rigid_m,
                   r.mean_rotation_error_rigid_deg);
    }
  }
  std::fprintf(stderr, " -> %s\n", output.c_str());
}

void RunLocalize(const LocalizeArgs& a) {
  CheckOutputFile(a.output, {a.map_dir, a.dataset});
  const Map map = ReadMap(a.map_dir);
  DatasetOptions dataset_options;
  dataset_options.first_frame = a.first_frame;
  dataset_options.num_frames = a.num_frames;
  dataset_options.camera_yaml = a.camera_yaml;
  const Dataset dataset = LoadDataset(a.dataset, dataset_options);
  LocalizationPipelineOptions pipeline;
  pipeline.localizer = ResolveOptions(a);
  std::vector<TimedPose> trajectory;
  std::vector<std::vector<Particle>> sets;
  const LocalizationReport r = LocalizeSequence(
      map, dataset, pipeline, &trajectory,
      a.particles_out.empty() && a.html.empty() ? nullptr : &sets);
  WriteTumTrajectory(a.output, trajectory,
                     "monomap localize --method " + a.method);
  if (!a.particles_out.empty()) WriteParticleSets(a.particles_out, sets);
  if (!a.report.empty()) {
    WriteFileAtomic(a.report, r.ToJson().dump(2) + "\n");
  }
  if (!a.html.empty()) WriteHtml(a, dataset, trajectory, sets, r);
  PrintSummary(r, a.output);
}

}  // namespace

void RegisterLocalizeCommand(CLI::App& app) {
  auto a = std::make_shared<LocalizeArgs>();
  CLI::App* cmd = app.add_subcommand(
      "localize", "Localize a dataset's frames in a map (MCL or MCC)");
  cmd->add_option("map", a->map_dir, "Map directory")->required();
  cmd->add_option("dataset", a->dataset, "Dataset directory")->required();
  cmd->add_option("-o,--output", a->output, "Estimated trajectory (TUM)")
      ->required();
  cmd->add_option("--method", a->method, "mcl | mcc")
      ->check(CLI::IsMember({"mcl", "mcc"}));
  cmd->add_option("--init", a->init, "global | pose")
      ->check(CLI::IsMember({"global", "pose"}));
  cmd->add_option("--init-pose", a->init_pose,
                  "With --init pose: the pose T_world_cam to start around, "
                  "as \"tx ty tz qx qy qz qw\" (default: the first frame's "
                  "odometry pose)");
  cmd->add_option("--state", a->state, "planar | 6dof")
      ->check(CLI::IsMember({"planar", "6dof"}));
  AddFilterOptions(cmd, a.get());
  cmd->add_option("--camera", a->camera_yaml,
                  "Calibration to use instead of DATASET/camera.yaml (e.g. "
                  "from 'monomap calibrate')");
  AddFrameRangeOptions(cmd, &a->first_frame, &a->num_frames);
  cmd->add_option("--seed", a->options.seed, "Seed of the filter")
      ->capture_default_str();
  AddOutputOptions(cmd, a.get());
  cmd->callback([a]() { RunLocalize(*a); });
}

}  // namespace monomap
