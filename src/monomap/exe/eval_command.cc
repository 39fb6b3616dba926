// monomap eval points MAP_DIR (--plane STRUCTURE.yaml | --surface CLOUD.ply)
// monomap eval planes MAP_DIR (--plane STRUCTURE.yaml | --surface CLOUD.ply)
// monomap eval checkerboard MAP_DIR --structure STRUCTURE.yaml
// monomap eval board-poses DATASET --structure STRUCTURE.yaml -o REF.txt
//     [--camera CAMERA.yaml] [--anchor TRAJ.txt] [--first-frame F --frames N]
// monomap eval lens MAP_DIR [--trajectory REF.txt]
// monomap eval structure MAP_DIR --structure STRUCTURE_DIR
//     [--align none|first-pose --groundtruth GT.txt]
// monomap eval render MAP_DIR DATASET [--stride N] [--width W] [--wrong-offset
// M]
//     [--first-frame F --frames N] [--align none|first-pose]
// monomap eval trajectory ESTIMATE.txt GROUNDTRUTH.txt [--align ...]
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>

#include "monomap/eval/board_poses.h"
#include "monomap/eval/checkerboard_accuracy.h"
#include "monomap/eval/lens_residuals.h"
#include "monomap/eval/point_accuracy.h"
#include "monomap/eval/render_fidelity.h"
#include "monomap/eval/report_json.h"
#include "monomap/eval/structure_accuracy.h"
#include "monomap/eval/trajectory_metrics.h"
#include "monomap/exe/commands.h"
#include "monomap/io/dataset.h"
#include "monomap/io/feature_table.h"
#include "monomap/io/map_format.h"
#include "monomap/io/ply.h"
#include "monomap/io/trajectory_io.h"
#include "monomap/util/error.h"
#include "monomap/util/file.h"

namespace monomap {

namespace {

// Distance from each point to the nearest camera centre of the trajectory
// (the "distance to the camera" that relative errors divide by).
std::vector<double> DistanceToTrajectory(
    const std::vector<Eigen::Vector3d>& points,
    const std::vector<TimedPose>& trajectory) {
  std::vector<double> d(points.size(), std::numeric_limits<double>::infinity());
  for (size_t i = 0; i < points.size(); ++i) {
    for (const auto& p : trajectory) {
      d[i] = std::min(d[i], (points[i] - p.world_from_cam.translation).norm());
    }
  }
  return d;
}

void PrintOrWrite(const nlohmann::json& j, const std::string& table,
                  const std::string& json_path) {
  std::cout << table;
  if (!json_path.empty()) WriteFileAtomic(json_path, j.dump(2) + "\n");
}

}  // namespace

void RegisterEvalCommand(CLI::App& app) {
  CLI::App* eval = app.add_subcommand("eval", "Accuracy figures");
  eval->require_subcommand(1);

  struct PointArgs {
    std::string map_dir, plane_yaml, surface_ply, json;
    int plane_label = -2;  // -2: all points, -1: points on no plane
    bool largest_plane = false;
  };
  auto pa = std::make_shared<PointArgs>();
  CLI::App* points = eval->add_subcommand(
      "points", "Point error against a ground-truth plane or surface cloud");
  points->add_option("map", pa->map_dir, "Map directory")->required();
  auto* plane_opt = points->add_option("--plane", pa->plane_yaml,
                                       "Ground-truth structure YAML (plane)");
  auto* surface_opt = points->add_option("--surface", pa->surface_ply,
                                         "Ground-truth surface PLY");
  plane_opt->excludes(surface_opt);
  points->add_option("--plane-label", pa->plane_label,
                     "Evaluate only points with this plane label");
  points->add_flag("--largest-plane", pa->largest_plane,
                   "Evaluate only points of the plane with most points");
  points->add_option("--json", pa->json, "Write the figures as JSON");
  points->callback([pa]() {
    if (pa->plane_yaml.empty() == pa->surface_ply.empty()) {
      throw OptionsError(
          "eval points: give exactly one of --plane or "
          "--surface");
    }
    const Map map = ReadMap(pa->map_dir);
    int label = pa->plane_label;
    if (pa->largest_plane) {
      std::map<int, int> counts;
      for (const auto& l : map.landmarks) {
        if (l.plane_id >= 0) ++counts[l.plane_id];
      }
      if (counts.empty()) {
        throw StageError(pa->map_dir + ": map has no plane labels");
      }
      label =
          std::max_element(counts.begin(), counts.end(), [](auto& a, auto& b) {
            return a.second < b.second;
          })->first;
    }
    std::vector<Eigen::Vector3d> xs;
    for (const auto& l : map.landmarks) {
      if (label == -2 || l.plane_id == label) xs.push_back(l.x_in_world);
    }
    if (xs.empty()) throw StageError("no points to evaluate");
    const auto dist = DistanceToTrajectory(xs, map.trajectory);
    PointAccuracy acc;
    if (!pa->plane_yaml.empty()) {
      acc = EvaluatePointsAgainstPlane(
          xs, dist, ReadGroundTruthPlaneYaml(pa->plane_yaml));
    } else {
      const NearestNeighborIndex index(ReadPlyPoints(pa->surface_ply));
      acc = EvaluatePointsAgainstCloud(xs, dist, index);
    }
    nlohmann::json j = ToJson(acc);
    j["plane_label"] = label;
    PrintOrWrite(j, FormatTable(acc), pa->json);
  });

  struct PlaneArgs {
    std::string map_dir, surface_ply, plane_yaml, json;
    double spacing_m = 0.01;
  };
  auto pl = std::make_shared<PlaneArgs>();
  CLI::App* planes = eval->add_subcommand(
      "planes",
      "Distance of samples of each textured plane (its seen texels) to the "
      "true surface");
  planes->add_option("map", pl->map_dir, "Map directory")->required();
  auto* pl_surface =
      planes->add_option("--surface", pl->surface_ply, "Ground-truth PLY");
  auto* pl_plane = planes->add_option("--plane", pl->plane_yaml,
                                      "Ground-truth structure YAML (plane)");
  pl_surface->excludes(pl_plane);
  planes->add_option("--spacing", pl->spacing_m, "Sample spacing (m)");
  planes->add_option("--json", pl->json, "Write the figures as JSON");
  planes->callback([pl]() {
    if (pl->plane_yaml.empty() == pl->surface_ply.empty()) {
      throw OptionsError(
          "eval planes: give exactly one of --plane or "
          "--surface");
    }
    const Map map = ReadMap(pl->map_dir);
    std::unique_ptr<NearestNeighborIndex> index;
    Plane truth;
    if (!pl->surface_ply.empty()) {
      index = std::make_unique<NearestNeighborIndex>(
          ReadPlyPoints(pl->surface_ply));
    } else {
      truth = ReadGroundTruthPlaneYaml(pl->plane_yaml);
    }
    nlohmann::json j;
    j["num_planes"] = map.planes.size();
    j["planes"] = nlohmann::json::array();
    std::vector<double> all;
    std::string table = "plane  samples  median(mm)  p90(mm)  max(mm)\n";
    for (const TexturedPlane& p : map.planes) {
      // Texel centres the images saw, one every `spacing` metres.
      const int stride =
          std::max(1, static_cast<int>(pl->spacing_m * p.pixels_per_meter));
      std::vector<double> d;
      for (int r = 0; r < p.texture.rows; r += stride) {
        for (int c = 0; c < p.texture.cols; c += stride) {
          if (p.texture.channels() == 4 &&
              p.texture.at<cv::Vec4b>(r, c)[3] == 0) {
            continue;
          }
          const Eigen::Vector3d x = p.WorldFromTexture(Eigen::Vector2d(c, r));
          d.push_back(index ? index->NearestDistance(x)
                            : std::abs(truth.SignedDistance(x)));
        }
      }
      all.insert(all.end(), d.begin(), d.end());
      const ErrorStats e = ComputeErrorStats(d);
      j["planes"].push_back({{"id", p.id}, {"distance_m", ToJson(e)}});
      char line[160];
      std::snprintf(line, sizeof(line), "%5d  %7zu  %10.2f  %7.2f  %7.2f\n",
                    p.id, e.count, e.median * 1e3, e.p90 * 1e3, e.max * 1e3);
      table += line;
    }
    const ErrorStats e = ComputeErrorStats(all);
    j["all"] = ToJson(e);
    char line[160];
    std::snprintf(line, sizeof(line), "  all  %7zu  %10.2f  %7.2f  %7.2f\n",
                  e.count, e.median * 1e3, e.p90 * 1e3, e.max * 1e3);
    table += line;
    PrintOrWrite(j, table, pl->json);
  });

  struct BoardArgs {
    std::string map_dir, structure, json;
  };
  auto ba = std::make_shared<BoardArgs>();
  CLI::App* board = eval->add_subcommand(
      "checkerboard",
      "Find a known checkerboard in the plane textures and compare its "
      "corners, mapped to 3D, with their true positions");
  board->add_option("map", ba->map_dir, "Map directory")->required();
  board
      ->add_option("--structure", ba->structure,
                   "Ground-truth structure YAML with a 'chessboard' entry")
      ->required();
  board->add_option("--json", ba->json, "Write the figures as JSON");
  board->callback([ba]() {
    const Map map = ReadMap(ba->map_dir);
    const CheckerboardSpec spec = ReadCheckerboardYaml(ba->structure);
    const CheckerboardAccuracy acc = EvaluateCheckerboard(map, spec);
    nlohmann::json j;
    j["found"] = acc.found;
    j["plane_id"] = acc.plane_id;
    j["corners_found"] = acc.corners_found;
    j["corners_expected"] = spec.inner_corners_x * spec.inner_corners_y;
    if (acc.found) {
      j["detector"] = acc.detector;
      j["error_m"] = ToJson(acc.error_m);
    }
    char table[320];
    std::snprintf(table, sizeof(table),
                  "checkerboard %dx%d: %s in plane %d%s%s, corner error mean "
                  "%.2f mm, median %.2f mm, max %.2f mm\n",
                  spec.inner_corners_x, spec.inner_corners_y,
                  acc.found ? "found" : "NOT found", acc.plane_id,
                  acc.found ? " by " : "", acc.detector.c_str(),
                  acc.error_m.mean * 1e3, acc.error_m.median * 1e3,
                  acc.error_m.max * 1e3);
    PrintOrWrite(j, table, ba->json);
    if (!acc.found) throw StageError("checkerboard not found in any texture");
  });

  struct BoardPoseArgs {
    std::string dataset, structure, output, json, camera_yaml, anchor;
    int first_frame = 0, num_frames = -1;
    BoardPoseOptions options;
  };
  auto bp = std::make_shared<BoardPoseArgs>();
  CLI::App* board_poses = eval->add_subcommand(
      "board-poses",
      "A reference trajectory from the images: the camera pose of every "
      "frame that shows the known checkerboard (PnP on its corners)");
  board_poses->add_option("dataset", bp->dataset, "Dataset directory")
      ->required();
  board_poses
      ->add_option("--structure", bp->structure,
                   "Ground-truth structure YAML with a 'chessboard' entry")
      ->required();
  board_poses
      ->add_option("-o,--output", bp->output,
                   "Reference trajectory to write (TUM, world_from_cam)")
      ->required();
  board_poses
      ->add_option("--max-rms", bp->options.max_rms_px,
                   "Refuse poses whose corner RMS error exceeds this (px)")
      ->check(CLI::PositiveNumber);
  board_poses->add_option("--camera", bp->camera_yaml,
                          "Calibration to use instead of DATASET/camera.yaml "
                          "(e.g. from 'monomap calibrate')");
  board_poses->add_option(
      "--anchor", bp->anchor,
      "Express the poses in this trajectory's frame (TUM), tied at the first "
      "frame with a pose: e.g. the odometry a map was built in");
  AddFrameRangeOptions(board_poses, &bp->first_frame, &bp->num_frames);
  board_poses->add_option("--json", bp->json, "Write the figures as JSON");
  board_poses->callback([bp]() {
    DatasetOptions dataset_options;
    dataset_options.load_groundtruth = false;
    dataset_options.camera_yaml = bp->camera_yaml;
    dataset_options.first_frame = bp->first_frame;
    dataset_options.num_frames = bp->num_frames;
    const Dataset dataset = LoadDataset(bp->dataset, dataset_options);
    const CheckerboardSpec spec = ReadCheckerboardYaml(bp->structure);
    std::vector<double> timestamps;
    std::vector<Rigid3d> hints;  // odometry: tells the board's half turns apart
    for (const DatasetFrame& f : dataset.frames) {
      timestamps.push_back(f.timestamp);
      hints.push_back(f.odometry_world_from_cam);
    }
    const BoardPoseReport report = EstimateBoardPoses(
        [&](int i) { return dataset.LoadImage(static_cast<size_t>(i)); },
        timestamps, hints, dataset.camera, spec, bp->options);
    if (report.poses.empty()) {
      throw StageError(bp->dataset +
                       ": the checkerboard was found in no frame");
    }
    std::vector<TimedPose> poses = report.poses;
    if (!bp->anchor.empty()) {
      Rigid3d anchor_pose;
      if (!InterpolatePose(ReadTumTrajectory(bp->anchor), poses[0].timestamp,
                           0.1, &anchor_pose)) {
        throw InputError(bp->anchor, "timestamps",
                         "no pose at the first board frame's time " +
                             std::to_string(poses[0].timestamp));
      }
      // anchor_from_board_world, the same for every frame.
      const Rigid3d change = anchor_pose * poses[0].world_from_cam.Inverse();
      for (TimedPose& p : poses) p.world_from_cam = change * p.world_from_cam;
    }
    WriteTumTrajectory(bp->output, poses,
                       "camera poses from checkerboard PnP (monomap eval "
                       "board-poses)");
    nlohmann::json j;
    j["frames"] = report.frames;
    j["poses"] = report.poses.size();
    j["rms_px"] = ToJson(report.rms_px);
    j["rotation_sigma_deg"] = ToJson(report.rotation_sigma_deg);
    j["position_sigma_m"] = ToJson(report.position_sigma_m);
    char table[400];
    std::snprintf(table, sizeof(table),
                  "board poses: %zu of %d frames -> %s\n"
                  "corner RMS error (px): median %.3f, max %.3f\n"
                  "formal sigma, rotation (deg): median %.4f, max %.4f\n"
                  "formal sigma, camera centre (mm): median %.3f, max %.3f\n",
                  report.poses.size(), report.frames, bp->output.c_str(),
                  report.rms_px.median, report.rms_px.max,
                  report.rotation_sigma_deg.median,
                  report.rotation_sigma_deg.max,
                  report.position_sigma_m.median * 1e3,
                  report.position_sigma_m.max * 1e3);
    PrintOrWrite(j, table, bp->json);
  });

  struct LensArgs {
    std::string map_dir, trajectory, json;
    LensResidualOptions options;
  };
  auto la = std::make_shared<LensArgs>();
  CLI::App* lens = eval->add_subcommand(
      "lens",
      "Check the lens calibration at the rim: residuals of the map's tracks, "
      "fixed by their central observations, by distance from the centre");
  lens->add_option("map", la->map_dir, "Map directory (with features.csv)")
      ->required();
  lens->add_option("--trajectory", la->trajectory,
                   "Poses to trust (TUM), e.g. from 'eval board-poses'; "
                   "default: the map's own");
  lens->add_option("--centre-radius", la->options.centre_radius_px,
                   "Observations within this radius (px) fix the points")
      ->check(CLI::PositiveNumber);
  lens->add_option("--json", la->json, "Write the figures as JSON");
  lens->callback([la]() {
    const Map map = ReadMap(la->map_dir);
    const auto tracks =
        ReadFeatureTable(std::filesystem::path(la->map_dir) / "features.csv");
    std::vector<Rigid3d> world_from_cam;
    if (la->trajectory.empty()) {
      for (const TimedPose& p : map.trajectory) {
        world_from_cam.push_back(p.world_from_cam);
      }
    } else {
      const auto reference = ReadTumTrajectory(la->trajectory);
      for (const TimedPose& p : map.trajectory) {
        Rigid3d pose;
        if (!InterpolatePose(reference, p.timestamp, 0.1, &pose)) {
          throw InputError(
              la->trajectory, "timestamps",
              "no pose at the map's frame time " + std::to_string(p.timestamp));
        }
        world_from_cam.push_back(pose);
      }
    }
    const LensResidualReport report =
        EvaluateLensResiduals(map.camera, world_from_cam, tracks, la->options);
    nlohmann::json j;
    j["tracks_used"] = report.tracks_used;
    j["rings"] = nlohmann::json::array();
    std::string table = "tracks used: " + std::to_string(report.tracks_used) +
                        "\nradius (px)   observations   radial mean  "
                        "radial median  tangential median (px)\n";
    for (const LensResidualRing& r : report.rings) {
      j["rings"].push_back({{"min_radius_px", r.min_radius_px},
                            {"max_radius_px", r.max_radius_px},
                            {"count", r.count},
                            {"radial_mean_px", r.radial_mean_px},
                            {"radial_median_px", r.radial_median_px},
                            {"tangential_median_px", r.tangential_median_px}});
      char line[160];
      std::snprintf(line, sizeof(line),
                    "%4.0f-%-4.0f %14d %13.3f %14.3f %18.3f\n", r.min_radius_px,
                    r.max_radius_px, r.count, r.radial_mean_px,
                    r.radial_median_px, r.tangential_median_px);
      table += line;
    }
    PrintOrWrite(j, table, la->json);
  });

  struct StructureArgs {
    std::string map_dir, structure_dir, align = "none", groundtruth, json;
    StructureAccuracyOptions options;  // the project's matching thresholds
  };
  auto sa = std::make_shared<StructureArgs>();
  CLI::App* structure = eval->add_subcommand(
      "structure",
      "Compare the map with a world's true planes (a simulated dataset's "
      "structure/ directory): point errors, plane matches, precision and "
      "recall");
  structure->add_option("map", sa->map_dir, "Map directory")->required();
  structure
      ->add_option("--structure", sa->structure_dir,
                   "Ground-truth structure as a map directory (the "
                   "simulator writes DATASET/structure)")
      ->required();
  structure
      ->add_option("--align", sa->align,
                   "none: the map is in the truth's frame (the simulator's "
                   "odometry starts at the true pose); first-pose: align "
                   "the map's first trajectory pose to --groundtruth")
      ->check(CLI::IsMember({"none", "first-pose"}))
      ->capture_default_str();
  structure->add_option("--groundtruth", sa->groundtruth,
                        "Ground-truth trajectory (TUM) for --align "
                        "first-pose");
  structure->add_option("--json", sa->json, "Write the figures as JSON");
  structure->callback([sa]() {
    const bool first_pose = sa->align == "first-pose";
    if (first_pose && sa->groundtruth.empty()) {
      throw OptionsError(
          "eval structure: --align first-pose needs "
          "--groundtruth");
    }
    if (!first_pose && !sa->groundtruth.empty()) {
      throw OptionsError(
          "eval structure: --groundtruth is only used with "
          "--align first-pose");
    }
    Map map = ReadMap(sa->map_dir);
    const Map truth = ReadMap(sa->structure_dir);
    // Relative point errors divide by each landmark's mean depth, which
    // points.ply does not hold: recompute it from the feature table.
    const std::filesystem::path features =
        std::filesystem::path(sa->map_dir) / "features.csv";
    std::error_code ec;  // a loop or a FIFO: no features, not a throw
    const bool have_features = std::filesystem::is_regular_file(features, ec);
    if (!have_features) {
      std::fprintf(stderr,
                   "monomap: note: %s missing: relative point errors use "
                   "the distance to the nearest camera\n",
                   features.string().c_str());
    }
    SetLandmarkDepths(
        have_features ? ReadFeatureTable(features) : std::vector<Track>(),
        &map);
    Rigid3d truth_from_map;
    if (first_pose) {
      truth_from_map =
          AlignTrajectories(map.trajectory, ReadTumTrajectory(sa->groundtruth),
                            Alignment::kFirstPose)
              .rigid;
    }
    const StructureAccuracy acc =
        EvaluateStructure(map, truth, truth_from_map, sa->options);
    nlohmann::json j = ToJson(acc);
    j["alignment"] = sa->align;
    j["relative_error_depth"] = have_features
                                    ? "mean_distance_to_observing_cameras"
                                    : "distance_to_nearest_camera";
    j["options"] = {
        {"max_match_angle_deg", sa->options.max_match_angle_deg},
        {"max_match_offset_m", sa->options.max_match_offset_m},
        {"polygon_margin_m", sa->options.polygon_margin_m},
        {"min_observed_landmarks", sa->options.min_observed_landmarks},
        {"observed_distance_m", sa->options.observed_distance_m}};
    PrintOrWrite(
        j,
        "structure accuracy (alignment " + sa->align + ")\n" + FormatTable(acc),
        sa->json);
  });

  struct RenderArgs {
    std::string map_dir, dataset, align = "none", json;
    int stride = 5, first_frame = 0, num_frames = -1;
    double wrong_offset_m = 0.05;
    RenderFidelityOptions options;
  };
  auto ra = std::make_shared<RenderArgs>();
  CLI::App* render = eval->add_subcommand(
      "render",
      "Texture fidelity: render the map from a dataset's ground-truth poses "
      "and compare with its images (NCC, gain-compensated PSNR)");
  render->add_option("map", ra->map_dir, "Map directory")->required();
  render
      ->add_option("dataset", ra->dataset,
                   "Dataset with groundtruth.txt (best: frames the map was "
                   "not built from)")
      ->required();
  render->add_option("--stride", ra->stride, "Compare every n-th frame")
      ->check(CLI::Range(1, 1000000))
      ->capture_default_str();
  render
      ->add_option("--width", ra->options.width,
                   "Compare at this width (0: the camera's)")
      ->capture_default_str();
  render
      ->add_option("--min-coverage", ra->options.min_coverage,
                   "Skip frames whose render covers less of the image")
      ->capture_default_str();
  AddFrameRangeOptions(render, &ra->first_frame, &ra->num_frames);
  render
      ->add_option("--align", ra->align,
                   "none: the map is in the ground truth's frame; "
                   "first-pose: align the map's first trajectory pose with "
                   "the dataset's ground truth at that time (same run)")
      ->check(CLI::IsMember({"none", "first-pose"}))
      ->capture_default_str();
  render
      ->add_option("--wrong-offset", ra->wrong_offset_m,
                   "Also compare renders from the true poses moved this far "
                   "(m) along the camera's x axis: how much better the true "
                   "pose matches (0: skip)")
      ->check(CLI::Range(0.0, 1e3))
      ->capture_default_str();
  render->add_option("--json", ra->json, "Write the figures as JSON");
  render->callback([ra]() {
    const Map map = ReadMap(ra->map_dir);
    DatasetOptions dataset_options;
    dataset_options.first_frame = ra->first_frame;
    dataset_options.num_frames = ra->num_frames;
    // Alignment needs the ground truth at the map's first pose, which may
    // lie before --first-frame: load it from the whole dataset.
    const Dataset dataset = LoadDataset(ra->dataset, dataset_options);
    if (!dataset.has_groundtruth) {
      throw InputError(ra->dataset +
                       ": no groundtruth.txt: eval render "
                       "renders from ground-truth poses");
    }
    Rigid3d map_from_truth;
    if (ra->align == "first-pose") {
      std::vector<TimedPose> truth;
      for (const DatasetFrame& f : LoadDataset(ra->dataset).frames) {
        truth.push_back({f.timestamp, *f.groundtruth_world_from_cam});
      }
      map_from_truth =
          AlignTrajectories(truth, map.trajectory, Alignment::kFirstPose).rigid;
    }
    std::vector<Rigid3d> poses;
    std::vector<cv::Mat> images;
    std::vector<int> frames;
    for (size_t i = 0; i < dataset.frames.size();
         i += static_cast<size_t>(ra->stride)) {
      poses.push_back(map_from_truth *
                      *dataset.frames[i].groundtruth_world_from_cam);
      images.push_back(dataset.LoadImage(i));
      frames.push_back(ra->first_frame + static_cast<int>(i));
    }
    const RenderFidelity f = EvaluateRenderFidelity(
        map, dataset.camera, poses, images, frames, ra->options);
    nlohmann::json j = ToJson(f);
    j["alignment"] = ra->align;
    j["stride"] = ra->stride;
    j["width"] = ra->options.width;
    std::string text =
        "texture fidelity (alignment " + ra->align + ")\n" + FormatTable(f);
    if (ra->wrong_offset_m > 0) {
      // The same frames from a wrong pose: a render that matched any pose
      // equally well would say nothing about where the camera is.
      std::vector<Rigid3d> wrong;
      for (const Rigid3d& p : poses) {
        wrong.push_back(p * Rigid3d(Eigen::Quaterniond::Identity(),
                                    {ra->wrong_offset_m, 0.0, 0.0}));
      }
      const RenderFidelity w = EvaluateRenderFidelity(
          map, dataset.camera, wrong, images, frames, ra->options);
      int both = 0, true_better = 0;
      for (const FrameFidelity& a : f.frames) {
        for (const FrameFidelity& b : w.frames) {
          if (b.frame != a.frame) continue;
          ++both;
          true_better += a.ncc > b.ncc ? 1 : 0;
        }
      }
      const double share =
          both > 0 ? static_cast<double>(true_better) / both : 0.0;
      j["wrong_pose"] = {{"offset_m", ra->wrong_offset_m},
                         {"ncc", ToJson(w.ncc)},
                         {"compared", both},
                         {"true_pose_better", share}};
      char line[200];
      std::snprintf(line, sizeof(line),
                    "poses moved %.3f m along camera x: NCC median %.3f "
                    "(true poses %.3f); the true pose matches better in "
                    "%d of %d frames\n",
                    ra->wrong_offset_m, w.ncc.median, f.ncc.median, true_better,
                    both);
      text += line;
    }
    PrintOrWrite(j, text, ra->json);
  });

  struct TrajArgs {
    std::string estimate, groundtruth, align = "se3", json;
    int delta = 1;
  };
  auto ta = std::make_shared<TrajArgs>();
  CLI::App* traj = eval->add_subcommand(
      "trajectory", "Absolute and relative pose error of a TUM trajectory");
  traj->add_option("estimate", ta->estimate, "Estimated trajectory (TUM)")
      ->required();
  traj->add_option("groundtruth", ta->groundtruth,
                   "Ground-truth trajectory (TUM)")
      ->required();
  traj->add_option("--align", ta->align, "none | first | se3 | sim3")
      ->check(CLI::IsMember({"none", "first", "se3", "sim3"}));
  traj->add_option("--delta", ta->delta, "Frame delta of the relative error");
  traj->add_option("--json", ta->json, "Write the figures as JSON");
  traj->callback([ta]() {
    const auto est = ReadTumTrajectory(ta->estimate);
    const auto gt = ReadTumTrajectory(ta->groundtruth);
    const Alignment alignment = ta->align == "none"    ? Alignment::kNone
                                : ta->align == "first" ? Alignment::kFirstPose
                                : ta->align == "se3"   ? Alignment::kSE3
                                                       : Alignment::kSim3;
    const TrajectoryErrors ate =
        AbsoluteTrajectoryError(est, gt, alignment, 1e-3);
    const TrajectoryErrors rpe = RelativePoseError(est, gt, ta->delta, 1e-3);
    nlohmann::json j;
    j["alignment"] = ta->align;
    j["ate"] = ToJson(ate);
    j["rpe"] = ToJson(rpe);
    j["rpe"]["delta_frames"] = ta->delta;
    PrintOrWrite(j,
                 "absolute trajectory error (" + ta->align + ")\n" +
                     FormatTable(ate) + "relative pose error (delta " +
                     std::to_string(ta->delta) + ")\n" + FormatTable(rpe),
                 ta->json);
  });
}

}  // namespace monomap
