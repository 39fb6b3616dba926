// monomap localize MAP_DIR DATASET --method mcl|mcc [--particles N]
//   [--init global|pose [--init-pose POSE]] [--state planar|6dof] -o TRAJ.txt
//   [--report R.json]
#include <algorithm>
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

void RegisterLocalizeCommand(CLI::App& app) {
  struct Args {
    std::string map_dir, dataset, output, report, particles_out, camera_yaml;
    std::string html;
    std::string init_pose;
    std::string method = "mcl", init = "pose", state = "planar";
    int particles = 1000;
    std::string mcc_size, measure_size;
    int mcc_top_k = -1;
    int refine_width = -1;
    double relocalize_ncc_drop = -1.0;
    int first_frame = 0, num_frames = -1;
    uint64_t seed = 1;
  };
  auto a = std::make_shared<Args>();
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
  cmd->add_option("--particles", a->particles,
                  "Particle budget (initial count and KLD maximum)")
      ->check(CLI::Range(10, 1000000));
  cmd->add_option("--mcc-size", a->mcc_size,
                  "WxH of the renders MCC tracks against (default 160x120)");
  cmd->add_option("--mcc-top-k", a->mcc_top_k,
                  "Heaviest particles MCC corrects per update (default 64)");
  cmd->add_option("--refine-width", a->refine_width,
                  "MCC: width of the render the estimate is refined against "
                  "(default: the camera's, up to 1024; 0: no refinement)")
      ->check(CLI::Range(0, 100000));
  cmd->add_option("--relocalize-ncc-drop", a->relocalize_ncc_drop,
                  "Inject particles over the area when the best particle's "
                  "NCC drops this far below its long-term average (0: "
                  "never; default: the localizer's, 0.035)");
  cmd->add_option("--measure-size", a->measure_size,
                  "WxH of the renders the weights compare (default 80x60)");
  cmd->add_option("--camera", a->camera_yaml,
                  "Calibration to use instead of DATASET/camera.yaml (e.g. "
                  "from 'monomap calibrate')");
  AddFrameRangeOptions(cmd, &a->first_frame, &a->num_frames);
  cmd->add_option("--seed", a->seed, "Seed of the filter");
  cmd->add_option("--report", a->report, "Per-step figures as JSON");
  cmd->add_option(
      "--particles-out", a->particles_out,
      "Write the particle sets per step (CSV: step, camera position, "
      "orientation quaternion, log weight)");
  cmd->add_option("--html", a->html,
                  "Also write an HTML report of the run in the map (3D view "
                  "with the particles, errors if the dataset has ground "
                  "truth)");
  cmd->callback([a]() {
    CheckOutputFile(a->output, {a->map_dir, a->dataset});
    const Map map = ReadMap(a->map_dir);
    DatasetOptions dataset_options;
    dataset_options.first_frame = a->first_frame;
    dataset_options.num_frames = a->num_frames;
    dataset_options.camera_yaml = a->camera_yaml;
    const Dataset dataset = LoadDataset(a->dataset, dataset_options);
    LocalizationPipelineOptions pipeline;
    LocalizerOptions& options = pipeline.localizer;
    options.method = ParseLocalizationMethod(a->method);
    options.init.kind = ParseLocalizationInit(a->init);
    options.state = ParseLocalizationState(a->state);
    if (!a->init_pose.empty()) {
      if (options.init.kind != LocalizationInit::kPose) {
        throw OptionsError("--init-pose needs --init pose");
      }
      options.init.pose = ParsePose(a->init_pose, "--init-pose");
    }
    // The budget: the initial count and KLD-sampling's maximum.
    options.mcl.num_particles = a->particles;
    options.mcl.kld.max_particles = a->particles;
    options.mcl.kld.min_particles =
        std::min(options.mcl.kld.min_particles, a->particles);
    if (!a->mcc_size.empty()) {
      ParseImageSize(a->mcc_size, "--mcc-size", &options.mcc.corrector.width,
                     &options.mcc.corrector.height);
    }
    if (!a->measure_size.empty()) {
      ParseImageSize(a->measure_size, "--measure-size",
                     &options.mcl.measurement.width,
                     &options.mcl.measurement.height);
    }
    if (a->mcc_top_k >= 0) options.mcc.top_k = a->mcc_top_k;
    if (a->refine_width == 0) {
      options.mcc.refine_estimate = false;
    } else if (a->refine_width > 0) {
      if (a->refine_width < 16) {
        throw OptionsError("--refine-width: must be 0 or at least 16");
      }
      // The height follows the camera's aspect (MccCorrection).
      options.mcc.refinement.width = a->refine_width;
    }
    if (a->relocalize_ncc_drop >= 0) {
      options.recovery.relocalize_ncc_drop = a->relocalize_ncc_drop;
    }
    options.seed = a->seed;
    std::vector<TimedPose> trajectory;
    std::vector<std::vector<Particle>> sets;
    const LocalizationReport r = LocalizeSequence(
        map, dataset, pipeline, &trajectory,
        a->particles_out.empty() && a->html.empty() ? nullptr : &sets);
    WriteTumTrajectory(a->output, trajectory,
                       "monomap localize --method " + a->method);
    if (!a->particles_out.empty()) {
      // Camera position and orientation (world_from_cam, TUM order) of
      // every particle, for plotting the sets.
      std::string csv = "step,x,y,z,qx,qy,qz,qw,log_weight\n";
      char line[240];
      for (size_t s = 0; s < sets.size(); ++s) {
        for (const auto& p : sets[s]) {
          const auto& t = p.world_from_cam.translation;
          const auto& q = p.world_from_cam.rotation;
          std::snprintf(line, sizeof(line),
                        "%zu,%.5f,%.5f,%.5f,%.7f,%.7f,%.7f,%.7f,%.4f\n", s,
                        t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w(),
                        p.log_weight);
          csv += line;
        }
      }
      WriteFileAtomic(a->particles_out, csv);
    }
    if (!a->report.empty()) {
      WriteFileAtomic(a->report, r.ToJson().dump(2) + "\n");
    }
    if (!a->html.empty()) {
      // The run as `monomap report --localization` would read it back.
      ReportInputs in;
      in.map_dir = a->map_dir;
      in.command_line = CurrentCommandLine();
      LocalizationRunData run;
      run.name = a->method;
      run.sources = {a->output};
      run.trajectory = trajectory;
      for (const DatasetFrame& f : dataset.frames) {
        if (f.groundtruth_world_from_cam) {
          run.groundtruth.push_back(
              {f.timestamp, *f.groundtruth_world_from_cam});
        }
      }
      run.particles =
          ParticlePositions(sets, ReportOptions().max_particles_per_step);
      run.report = r.ToJson();
      in.localization.push_back(std::move(run));
      ThrowIfProblems(WriteReport(in, a->html), a->html);
    }
    std::fprintf(stderr, "monomap: localized %d frames in %.1f s", r.frames,
                 r.seconds);
    if (r.has_errors) {
      std::fprintf(stderr, ", rmse %.4f m, final %.4f m / %.3f deg",
                   r.rmse_translation_m, r.final_translation_error_m,
                   r.final_rotation_error_deg);
    }
    std::fprintf(stderr, " -> %s\n", a->output.c_str());
  });
}

}  // namespace monomap
