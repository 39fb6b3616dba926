// monomap build DATASET -o MAP_DIR [--report REPORT.json]
#include <cstdio>
#include <filesystem>
#include <memory>

#include "monomap/exe/commands.h"
#include "monomap/io/dataset.h"
#include "monomap/pipelines/mapping_pipeline.h"
#include "monomap/report/html_page.h"
#include "monomap/util/file.h"

namespace monomap {

void RegisterBuildCommand(CLI::App& app) {
  struct Args {
    std::string dataset;
    std::string output;
    std::string report;
    std::string html;
    std::string camera_yaml;
    int first_frame = 0;
    int num_frames = -1;
    bool no_bundle_adjustment = false;
    bool points_only = false;
    int ransac_iterations = 2000;
    int keyframe_interval = MappingOptions().keyframe_interval;
    int features = KltTrackerOptions().target_features;
    int detection_min_missing = KltTrackerOptions().detection_min_missing;
    bool no_affine = false;
    int affine_interval = KltTrackerOptions().affine_interval;
    double max_image_radius = 0.0;
    bool quiet = false;
    bool ba_verbose = false;
    double max_odometry_step_m = DatasetOptions().max_odometry_step_m;
    bool drop_odometry_jumps = false;
    BundleAdjustmentOptions ba;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "build", "Build a map (points, planes, textures) from a dataset");
  cmd->add_option("dataset", args->dataset, "Dataset directory")->required();
  cmd->add_option("-o,--output", args->output, "Map directory to write")
      ->required();
  cmd->add_option("--report", args->report,
                  "Write counts and per-stage timings as JSON");
  cmd->add_option("--html", args->html,
                  "Also write the map's HTML report (see 'monomap report')");
  cmd->add_option("--camera", args->camera_yaml,
                  "Calibration to use instead of DATASET/camera.yaml (e.g. "
                  "from 'monomap calibrate')");
  AddFrameRangeOptions(cmd, &args->first_frame, &args->num_frames);
  cmd->add_flag("--no-ba", args->no_bundle_adjustment,
                "Skip bundle adjustment (keep odometry poses)");
  cmd->add_flag("--points-only", args->points_only,
                "Stop after triangulation and bundle adjustment");
  cmd->add_option("--ransac-iterations", args->ransac_iterations,
                  "RANSAC hypotheses per plane");
  cmd->add_option("--keyframe-interval", args->keyframe_interval,
                  "Bundle-adjust every n-th frame (1: all frames)");
  cmd->add_option("--features", args->features,
                  "Features the tracker keeps alive per frame");
  cmd->add_option("--detection-min-missing", args->detection_min_missing,
                  "Detect new features only once this many are missing "
                  "(1: every frame short of --features)")
      ->check(CLI::Range(1, 1000000));
  cmd->add_option("--max-image-radius", args->max_image_radius,
                  "Leave observations farther than this from the principal "
                  "point (px) out of the geometry: where the calibration is "
                  "not known (0: use all)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--no-affine-refinement", args->no_affine,
                "Track frame to frame only (no alignment with each "
                "feature's reference patch)");
  cmd->add_option("--affine-interval", args->affine_interval,
                  "Align each feature with its reference patch every n-th "
                  "frame (corrections in between interpolated)")
      ->check(CLI::Range(1, 1000000));
  cmd->add_option("--odometry-translation-sigma",
                  args->ba.translation_sigma_fraction,
                  "Bundle adjustment's odometry prior: translation sigma per "
                  "step as a fraction of the step length")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--odometry-rotation-sigma-deg",
                  args->ba.rotation_sigma_floor_deg,
                  "Bundle adjustment's odometry prior: rotation sigma per "
                  "step (degrees)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--odometry-rotation-sigma-deg-per-m",
                  args->ba.rotation_sigma_deg_per_m,
                  "Bundle adjustment's odometry prior: rotation sigma added "
                  "per metre of the step (degrees)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--odometry-span", args->ba.span_poses,
                  "Bundle adjustment's odometry prior also between poses this "
                  "many adjusted poses (keyframes) apart (0: off); for "
                  "odometry whose error is per-frame jitter that does not "
                  "accumulate")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--odometry-span-rotation-sigma-deg",
                  args->ba.span_rotation_sigma_deg,
                  "Rotation sigma of the span priors (degrees)")
      ->check(CLI::PositiveNumber);
  cmd->add_flag("--refine-distortion", args->ba.refine_distortion,
                "Bundle adjustment refines the lens distortion coefficients");
  cmd->add_option("--max-odometry-step-m", args->max_odometry_step_m,
                  "Largest odometry motion between two samples (m); a "
                  "larger jump is refused as corrupt (0: no limit)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_flag("--drop-odometry-jumps", args->drop_odometry_jumps,
                "Drop odometry samples beyond --max-odometry-step-m (and "
                "list them) instead of refusing the dataset");
  cmd->add_flag("-q,--quiet", args->quiet, "No progress output");
  cmd->add_flag("--ba-verbose", args->ba_verbose,
                "Print the bundle adjustment solver's progress and report");
  cmd->callback([args]() {
    // Refused before minutes of work, and again under the lock at writing.
    CheckOutputDirectory(args->output, "map",
                         {args->dataset, args->camera_yaml});
    if (!args->report.empty()) {
      CheckOutputFile(args->report, {args->dataset, args->output}, "--report");
    }
    DatasetOptions dataset_options;
    dataset_options.first_frame = args->first_frame;
    dataset_options.num_frames = args->num_frames;
    dataset_options.camera_yaml = args->camera_yaml;
    dataset_options.max_odometry_step_m = args->max_odometry_step_m;
    if (args->drop_odometry_jumps) {
      dataset_options.odometry_jump_policy = DatasetOptions::JumpPolicy::kDrop;
    }
    // Ground truth is never used to build maps.
    dataset_options.load_groundtruth = false;
    const Dataset dataset = LoadDataset(args->dataset, dataset_options);
    for (const std::string& line : dataset.dropped_odometry_lines) {
      std::fprintf(stderr, "monomap: %s: odometry jump dropped\n",
                   line.c_str());
    }

    MappingOptions options;
    options.bundle_adjustment = args->ba;
    options.bundle_adjustment.enabled = !args->no_bundle_adjustment;
    options.points_only = args->points_only;
    options.bundle_adjustment.verbose = args->ba_verbose;
    options.planes.ransac_iterations = args->ransac_iterations;
    options.keyframe_interval = args->keyframe_interval;
    options.tracking.target_features = args->features;
    options.tracking.detection_min_missing = args->detection_min_missing;
    options.tracking.affine_refinement = !args->no_affine;
    options.tracking.affine_interval = args->affine_interval;
    options.max_observation_radius_px = args->max_image_radius;
    options.show_progress = !args->quiet;
    const MappingResult result = BuildMap(dataset, options);
    WriteMappingResult(args->output, result);
    const nlohmann::json report = result.report.ToJson();
    if (!args->report.empty()) {
      WriteFileAtomic(args->report, report.dump(2) + "\n");
    }
    if (!args->html.empty()) {
      ReportInputs in;
      in.map_dir = args->output;
      in.dataset_dir = args->dataset;
      in.command_line = CurrentCommandLine();
      ThrowIfProblems(WriteReport(in, args->html), args->html);
    }
    if (!args->quiet) {
      std::fprintf(stderr,
                   "monomap: %d frames, %zu tracks, %zu points, %zu planes "
                   "in %.2f s (%.1f frames/s) -> %s\n",
                   result.report.num_frames, result.tracks.size(),
                   result.map.landmarks.size(), result.map.planes.size(),
                   result.report.total_seconds,
                   result.report.num_frames / result.report.total_seconds,
                   args->output.c_str());
    }
  });
}

}  // namespace monomap
