// monomap build DATASET -o MAP_DIR [--report REPORT.json]
//
// The options bind to the fields of a default-constructed MappingOptions,
// so `--help` shows the library's defaults.
#include <cstdio>
#include <filesystem>
#include <memory>

#include "monomap/exe/commands.h"
#include "monomap/exe/growth_cell_maps.h"
#include "monomap/io/dataset.h"
#include "monomap/pipelines/mapping_pipeline.h"
#include "monomap/report/html_page.h"
#include "monomap/util/file.h"

namespace monomap {

namespace {

struct BuildArgs {
  std::string dataset;
  std::string output;
  std::string report;
  std::string html;
  std::string camera_yaml;
  int first_frame = 0;
  int num_frames = -1;
  // Negative flags, applied to `options` after parsing.
  bool no_bundle_adjustment = false;
  bool no_affine = false;
  bool no_split_tracks = false;
  double image_noise = -1.0;  // --image-noise; < 0: estimated
  bool no_merge_coplanar = false;
  bool no_see_through = false;
  bool no_grow_planes = false;
  bool grow_planes = false;  // the default; kept for older scripts
  std::string debug_growth;  // --debug-growth DIR
  bool plane_hypotheses = false;
  bool no_plane_hypotheses = false;  // the default; kept for older scripts
  bool no_direction_snap = false;
  bool quiet = false;
  bool drop_odometry_jumps = false;
  DatasetOptions dataset_options;
  MappingOptions options;
};

void AddTrackingOptions(CLI::App* cmd, KltTrackerOptions* o) {
  cmd->add_option("--features", o->target_features,
                  "Features the tracker keeps alive per frame")
      ->capture_default_str();
  cmd->add_option("--detection-min-missing", o->detection_min_missing,
                  "Detect new features only once this many are missing "
                  "(1: every frame short of --features)")
      ->check(CLI::Range(1, 1000000))
      ->capture_default_str();
  cmd->add_option("--affine-interval", o->affine_interval,
                  "Align each feature with its reference patch every n-th "
                  "frame (corrections in between interpolated)")
      ->check(CLI::Range(1, 1000000))
      ->capture_default_str();
}

void AddBundleAdjustmentOptions(CLI::App* cmd, BundleAdjustmentOptions* o) {
  cmd->add_option("--odometry-translation-sigma", o->translation_sigma_fraction,
                  "Bundle adjustment's odometry prior: translation sigma per "
                  "step as a fraction of the step length")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--odometry-rotation-sigma-deg", o->rotation_sigma_floor_deg,
                  "Bundle adjustment's odometry prior: rotation sigma per "
                  "step (degrees)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--odometry-rotation-sigma-deg-per-m",
                  o->rotation_sigma_deg_per_m,
                  "Bundle adjustment's odometry prior: rotation sigma added "
                  "per metre of the step (degrees)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--odometry-span", o->span_poses,
                  "Bundle adjustment's odometry prior also between poses this "
                  "many adjusted poses (keyframes) apart (0: off); for "
                  "odometry whose error is per-frame jitter that does not "
                  "accumulate")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--odometry-span-rotation-sigma-deg",
                  o->span_rotation_sigma_deg,
                  "Rotation sigma of the span priors (degrees)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--ba-loss", o->loss,
                  "Robust loss of bundle adjustment's reprojection residuals: "
                  "huber | cauchy (weighs the tail of mistracked "
                  "observations down harder) | none")
      ->check(CLI::IsMember({"huber", "cauchy", "none"}))
      ->capture_default_str();
  cmd->add_option("--ba-loss-scale", o->loss_scale_px,
                  "Scale of that loss (px): residuals beyond it are "
                  "weighted down")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_flag("!--no-planar-base", o->planar_base.enabled,
                "No planar-base prior in bundle adjustment (by default a "
                "dataset with odometry2d.txt and camera_mount.yaml is a "
                "wheeled base that stays level on the floor)");
  cmd->add_option("--planar-tilt-sigma-deg", o->planar_base.tilt_sigma_deg,
                  "Planar-base prior: sigma of the base's roll and pitch per "
                  "pose (degrees)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--planar-height-sigma", o->planar_base.height_sigma_m,
                  "Planar-base prior: sigma of the base's height per pose (m)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--ba-outlier-threshold", o->outlier_threshold_px,
                  "After bundle adjustment's first solve, observations with "
                  "a larger reprojection error (px) leave the problem and it "
                  "is solved again (0: one solve)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_flag("--refine-distortion", o->refine_distortion,
                "Bundle adjustment refines the lens distortion coefficients");
  cmd->add_flag("--ba-verbose", o->verbose,
                "Print the bundle adjustment solver's progress and report");
}

// Lens self-calibration (intrinsics_refinement.h).
void AddLensOptions(CLI::App* cmd, IntrinsicsRefinementOptions* o) {
  IntrinsicsRefinementOptions& lens = *o;
  cmd->add_flag("--refine-intrinsics", lens.enabled,
                "Lens self-calibration: bundle adjustment refines the focal "
                "length and k1, k2 (and with the flags below the principal "
                "point and k3) under a prior at the given calibration, where "
                "the data constrain them and both halves of the frames agree "
                "(the report says which and why)");
  cmd->add_flag("--lens-fix-focal{false}", lens.refine_focal,
                "With --refine-intrinsics: keep the given focal length");
  cmd->add_flag("--lens-refine-principal-point", lens.refine_principal_point,
                "With --refine-intrinsics: also try the principal point");
  cmd->add_flag("--lens-fix-radial{false}", lens.refine_radial,
                "With --refine-intrinsics: keep the given k1, k2");
  cmd->add_flag("--lens-refine-k3", lens.refine_k3,
                "With --refine-intrinsics: also try the third radial term k3 "
                "(trusted only with k1, k2)");
  cmd->add_flag("--lens-no-halves-check{false}", lens.check_halves,
                "With --refine-intrinsics: trust a group without checking "
                "that the first and second half of the frames agree on it");
  cmd->add_option("--lens-focal-sigma", lens.focal_sigma_fraction,
                  "Prior sigma of the focal length (fraction of fx)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--lens-principal-point-sigma",
                  lens.principal_point_sigma_fraction,
                  "Prior sigma of the principal point (fraction of width)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--lens-k1-sigma", lens.k1_sigma, "Prior sigma of k1")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--lens-k2-sigma", lens.k2_sigma, "Prior sigma of k2")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--lens-k3-sigma", lens.k3_sigma, "Prior sigma of k3")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
}

void AddPointTrustOptions(CLI::App* cmd, PointTrustOptions* o,
                          InlierRefinementOptions* refinement) {
  cmd->add_flag("!--raw-points", refinement->enabled,
                "Export plane inliers where triangulation put them, not "
                "moved to their plane's local offset");
  cmd->add_flag("--keep-all-points", o->keep_all,
                "Export every triangulated point to points.ply, also those "
                "the map does not trust (the report still counts them)");
  cmd->add_option("--min-point-track-length", o->min_track_length,
                  "Export only points seen in at least this many frames")
      ->check(CLI::Range(2, 1000000))
      ->capture_default_str();
  cmd->add_option("--max-point-reprojection-error",
                  o->max_mean_reprojection_error_px,
                  "Export only points whose mean reprojection error after "
                  "bundle adjustment is at most this (px)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--max-point-reprojection-ratio",
                  o->max_reprojection_error_median_ratio,
                  "Export only points whose mean reprojection error is also "
                  "at most this many times the median over the map's points "
                  "(0: off)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--min-point-angle", o->min_triangulation_angle_deg,
                  "Export only points whose observing rays span at least "
                  "this angle (degrees)")
      ->check(CLI::Range(0.0, 179.9))
      ->capture_default_str();
  cmd->add_option("--max-point-uncertainty", o->max_relative_uncertainty,
                  "Export only points whose predicted standard deviation at "
                  "1 px of tracking noise is at most this fraction of their "
                  "depth (0: off)")
      ->check(CLI::Range(0.0, 1e6))
      ->capture_default_str();
}

// Plane growth and the plane hypotheses (opt-in) it checks.
void AddGrowthOptions(CLI::App* cmd, BuildArgs* a) {
  MappingOptions& o = a->options;
  CLI::Option* no_grow = cmd->add_flag(
      "--no-grow-planes", a->no_grow_planes,
      "Bound each plane by its points only: do not grow its polygon over "
      "the image regions its plane explains (photo-consistent across views)");
  cmd->add_flag("--grow-planes", a->grow_planes,
                "Grow planes over what the images explain (the default; "
                "kept for older scripts)")
      ->excludes(no_grow);
  cmd->add_option("--debug-growth", a->debug_growth,
                  "Write why each cell of each plane did or did not join it "
                  "(an image per plane and cells.json) to this directory");
  CLI::Option* hypotheses = cmd->add_flag(
      "--plane-hypotheses", a->plane_hypotheses,
      "Also propose planes along the scene's directions through the points "
      "on no plane, kept only where the images confirm them");
  cmd->add_flag("--no-plane-hypotheses", a->no_plane_hypotheses,
                "Propose no plane hypotheses (the default; kept for older "
                "scripts)")
      ->excludes(hypotheses);
  cmd->add_option("--plane-hypothesis-offset-check",
                  o.growth.hypothesis_offset_depth_fraction,
                  "A plane hypothesis is kept only if the images prefer its "
                  "offset to offsets this fraction of its distance nearer "
                  "and farther (0: off)")
      ->check(CLI::Range(0.0, 0.5))
      ->capture_default_str();
}

// Plane growth's bars: which cells count as evidence, how far plain ones
// reach.
void AddGrowthTuningOptions(CLI::App* cmd, BuildArgs* a) {
  MappingOptions& o = a->options;
  cmd->add_option("--plane-growth-plain-run", o.growth.max_plain_run,
                  "Grown planes extend over plain (untextured) cells at "
                  "most this many cells from texture evidence")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--plane-growth-reach", o.growth.max_growth_cells,
                  "Grow a plane at most this many cells (about 12 image "
                  "pixels each) beyond its points' polygon (0: no growth)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--plane-growth-min-ncc", o.growth.min_ncc,
                  "A textured cell joins a plane if its views correlate "
                  "(NCC with the view of most parallax, median) at least "
                  "this much")
      ->check(CLI::Range(-0.99, 0.99))
      ->capture_default_str();
  cmd->add_option("--plane-growth-min-parallax", o.growth.min_parallax_deg,
                  "A cell's views must span at least this angle (deg)")
      ->check(CLI::Range(0.0, 89.0))
      ->capture_default_str();
  cmd->add_option("--plane-growth-min-plain-parallax",
                  o.growth.min_plain_parallax_deg,
                  "A plain cell's views must span at least this angle (deg)")
      ->check(CLI::Range(0.0, 89.0))
      ->capture_default_str();
  cmd->add_option("--plane-growth-min-cos", o.growth.min_cos_view_angle,
                  "Views at grazing angles (|cos| to the plane's normal "
                  "below this) do not count for a cell")
      ->check(CLI::Range(0.0, 0.99))
      ->capture_default_str();
  cmd->add_option("--plane-growth-occluder-dilation",
                  o.growth.occluder_dilation_cells,
                  "Another plane hides a cell from a view within this many "
                  "cells outside its polygon")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_flag("!--plane-growth-no-aperture-test", o.growth.aperture_test,
                "Count a textured cell as evidence even when its texture does "
                "not change along the direction the views' parallax moves it");
  cmd->add_flag("!--plane-growth-redraw-fitted", o.growth.keep_fitted_outline,
                "Redraw a grown plane's whole polygon as growth's cells "
                "instead of adding the grown cells to its points' polygon");
  cmd->add_flag("!--plane-growth-keep-hidden", o.growth.drop_hidden_cells,
                "Keep the cells of a plane's points' polygon that every view "
                "sees only through a plane meeting it (left out by default)");
  cmd->add_option("--plane-growth-aperture-ratio",
                  o.growth.aperture_max_ratio,
                  "A textured cell is evidence only if its patch changes at "
                  "least this much along the parallax as across it")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  cmd->add_flag("!--plane-growth-no-exposure-compensation",
                o.growth.compensate_exposure,
                "Compare plain cells' brightness across views without each "
                "view's exposure gain (estimated from the tracked features)");
}

void AddMappingOptions(CLI::App* cmd, BuildArgs* a) {
  MappingOptions& o = a->options;
  cmd->add_flag("--no-ba", a->no_bundle_adjustment,
                "Skip bundle adjustment (keep odometry poses)");
  cmd->add_flag("--points-only", o.points_only,
                "Stop after triangulation and bundle adjustment");
  cmd->add_option("--ransac-iterations", o.planes.ransac_iterations,
                  "RANSAC hypotheses per plane")
      ->capture_default_str();
  cmd->add_flag("--no-merge-coplanar", a->no_merge_coplanar,
                "Keep the plane segments that lie on one physical plane "
                "apart; by default they are merged");
  cmd->add_flag("!--no-extend-planes", o.planes.extend_to_absorbed,
                "Bound each plane by its inliers only; by default its polygon "
                "also covers the loose points next to it that lie on it "
                "within their uncertainty");
  cmd->add_flag("--no-see-through-check", a->no_see_through,
                "Keep the planes through which the cameras saw more of the "
                "map than lies on them; by default they are dropped");
  cmd->add_flag("--local-ghost-test", o.planes.local_ghost_test,
                "Reject a plane as another's noisy ghost only by its points "
                "over that plane's polygon, so a surface beside a plane (a "
                "recessed door) is kept");
  cmd->add_flag("--no-direction-snap", a->no_direction_snap,
                "Keep every plane's least-squares normal; by default a plane "
                "whose points allow it takes the direction of the scene's "
                "well-measured planes or one at right angles to them");
  cmd->add_option("--snap-max-angle", o.planes.snap_max_angle_deg,
                  "Largest angle (deg) a plane's normal is snapped by")
      ->capture_default_str();
  AddGrowthOptions(cmd, a);
  AddGrowthTuningOptions(cmd, a);
  cmd->add_option("--keyframe-interval", o.keyframes.interval,
                  "Bundle-adjust every n-th frame (1: all frames)")
      ->capture_default_str();
  cmd->add_option("--max-keyframe-covisibility", o.keyframes.max_covisibility,
                  "Thin the keyframes (every m-th) until a point is seen by "
                  "at most this many on average, so that slow runs adjust "
                  "in linear time (0: never)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  AddTrackingOptions(cmd, &o.tracking);
  cmd->add_option("--max-image-radius", o.max_observation_radius_px,
                  "Leave observations farther than this from the principal "
                  "point (px) out of the geometry: where the calibration is "
                  "not known (0: use all)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_flag("--no-affine-refinement", a->no_affine,
                "Track frame to frame only (no alignment with each "
                "feature's reference patch)");
  cmd->add_flag("--no-split-tracks", a->no_split_tracks,
                "Let a feature keep its id when its alignment with its "
                "reference patch fails (default: it goes on under a new id)");
  cmd->add_option("--image-noise", a->image_noise,
                  "The images' noise (grey levels) the alignment allows for "
                  "(default: estimated from the first frame; 0: none)")
      ->check(CLI::NonNegativeNumber);
  AddBundleAdjustmentOptions(cmd, &o.bundle_adjustment);
  AddLensOptions(cmd, &o.bundle_adjustment.intrinsics);
  AddPointTrustOptions(cmd, &o.point_trust, &o.inlier_refinement);
}

void RunBuild(const BuildArgs& a) {
  // Refused before minutes of work, and again under the lock at writing.
  CheckOutputDirectory(a.output, "map", {a.dataset, a.camera_yaml});
  if (!a.report.empty()) {
    CheckOutputFile(a.report, {a.dataset, a.output}, "--report");
  }
  if (!a.html.empty()) CheckOutputFile(a.html, {a.dataset, a.output}, "--html");
  if (!a.debug_growth.empty()) {
    CheckOption(!a.no_grow_planes, "--debug-growth",
                "cannot be combined with --no-grow-planes");
    CheckOutputDirectory(a.debug_growth, "growth-debug", {a.dataset, a.output},
                         "--debug-growth");
  }
  DatasetOptions dataset_options = a.dataset_options;
  if (a.drop_odometry_jumps) {
    dataset_options.odometry_jump_policy = DatasetOptions::JumpPolicy::kDrop;
  }
  dataset_options.first_frame = a.first_frame;
  dataset_options.num_frames = a.num_frames;
  dataset_options.camera_yaml = a.camera_yaml;
  // Ground truth is never used to build maps.
  dataset_options.load_groundtruth = false;
  const Dataset dataset = LoadDataset(a.dataset, dataset_options);
  for (const std::string& line : dataset.dropped_odometry_lines) {
    std::fprintf(stderr, "monomap: %s: odometry jump dropped\n", line.c_str());
  }

  MappingOptions options = a.options;
  options.bundle_adjustment.enabled = !a.no_bundle_adjustment;
  options.tracking.affine_refinement = !a.no_affine;
  options.tracking.split_on_failed_alignment = !a.no_split_tracks;
  if (a.image_noise >= 0.0) {
    options.tracking.estimate_noise = false;
    options.tracking.affine.noise_sigma = a.image_noise;
  }
  options.planes.merge_coplanar = !a.no_merge_coplanar;
  options.see_through.enabled = !a.no_see_through;
  options.growth.enabled = !a.no_grow_planes;
  options.growth.keep_cell_maps = !a.debug_growth.empty();
  options.hypotheses.enabled = a.plane_hypotheses;
  options.planes.snap_to_directions = !a.no_direction_snap;
  options.show_progress = !a.quiet;
  const MappingResult result = BuildMap(dataset, options);
  WriteMappingResult(a.output, result);
  if (!a.debug_growth.empty()) {
    WriteGrowthCellMaps(a.debug_growth, result.report.growth);
  }
  if (!a.report.empty()) {
    WriteFileAtomic(a.report, result.report.ToJson().dump(2) + "\n");
  }
  if (!a.html.empty()) {
    ReportInputs in;
    in.map_dir = a.output;
    in.dataset_dir = a.dataset;
    in.command_line = CurrentCommandLine();
    ThrowIfProblems(WriteReport(in, a.html), a.html);
  }
  if (!a.quiet) {
    const PointTrustReport& trust = result.report.point_trust;
    std::fprintf(stderr,
                 "monomap: %d frames, %zu tracks, %zu points exported (%d "
                 "untrusted %s), %zu planes in %.2f s (%.1f frames/s) -> %s\n",
                 result.report.num_frames, result.tracks.size(),
                 result.map.landmarks.size(),
                 trust.short_track + trust.reprojection_error +
                     trust.triangulation_angle + trust.uncertainty,
                 trust.keep_all ? "kept" : "left out", result.map.planes.size(),
                 result.report.total_seconds,
                 result.report.num_frames / result.report.total_seconds,
                 a.output.c_str());
  }
}

}  // namespace

void RegisterBuildCommand(CLI::App& app) {
  auto args = std::make_shared<BuildArgs>();
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
  AddMappingOptions(cmd, args.get());
  cmd->add_option("--max-odometry-step-m",
                  args->dataset_options.max_odometry_step_m,
                  "Largest odometry motion between two samples (m); a "
                  "larger jump is refused as corrupt (0: no limit)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_flag("--drop-odometry-jumps", args->drop_odometry_jumps,
                "Drop odometry samples beyond --max-odometry-step-m (and "
                "list them) instead of refusing the dataset");
  cmd->add_flag("-q,--quiet", args->quiet, "No progress output");
  cmd->callback([args]() { RunBuild(*args); });
}

}  // namespace monomap
