#include "monomap/pipelines/demo.h"

#include <algorithm>
#include <cstdio>

#include "monomap/eval/report_json.h"
#include "monomap/io/dataset.h"
#include "monomap/io/map_format.h"
#include "monomap/pipelines/mapping_pipeline.h"
#include "monomap/sim/simulate.h"
#include "monomap/sim/world.h"
#include "monomap/util/error.h"
#include "monomap/util/file.h"
#include "monomap/util/progress.h"

namespace monomap {

void DemoOptions::Check() const {
  CheckOption(!output_dir.empty(), "output_dir", "must not be empty");
  const std::vector<std::string> names = WorldNames();
  CheckOption(std::find(names.begin(), names.end(), world) != names.end(),
              "world", "unknown world '" + world + "'");
  CheckOption(num_frames >= 20, "num_frames",
              "must be at least 20 (the map needs motion)");
  CheckOption(width >= 64 && height >= 48, "width/height",
              "must be at least 64x48");
  structure.Check();
  mapping.Check();
  if (given_camera) {
    CheckOption(given_camera->width == width && given_camera->height == height,
                "given_camera", "must have the simulated image size");
    given_camera->Check();
  }
  CheckOption(rpe_delta_frames >= 1, "rpe_delta_frames", "must be at least 1");
  if (localization.enabled) localization.Check();
}

namespace {

// The simulated dataset's ground truth and odometry, and the dataset as
// the mapping pipeline sees it (no ground truth).
struct DemoDataset {
  Dataset blind;
  std::vector<TimedPose> groundtruth, odometry;
};

DemoDataset LoadDemoDataset(const std::filesystem::path& dir) {
  DemoDataset d;
  d.blind = LoadDataset(dir);
  if (!d.blind.has_groundtruth) {
    throw StageError("demo: the simulated dataset has no ground truth");
  }
  for (DatasetFrame& f : d.blind.frames) {
    d.groundtruth.push_back({f.timestamp, *f.groundtruth_world_from_cam});
    d.odometry.push_back({f.timestamp, f.odometry_world_from_cam});
    f.groundtruth_world_from_cam.reset();
  }
  d.blind.has_groundtruth = false;
  return d;
}

// The map against the simulator's true planes and trajectory. The map
// lives in the odometry frame; both odometry and ground truth start at the
// same pose, and the first-pose alignment of the odometry makes any
// residual offset explicit. Returns world_from_map.
Rigid3d EvaluateDemoMap(const Map& map, const DemoDataset& d,
                        const DemoOptions& options, DemoReport* report) {
  const Map truth = ReadMap(report->dataset_dir / "structure");
  const Sim3d world_from_map =
      AlignTrajectories(d.odometry, d.groundtruth, Alignment::kFirstPose);
  report->structure =
      EvaluateStructure(map, truth, world_from_map.rigid, options.structure);
  report->ate_refined = AbsoluteTrajectoryError(map.trajectory, d.groundtruth,
                                                Alignment::kFirstPose);
  report->ate_odometry =
      AbsoluteTrajectoryError(d.odometry, d.groundtruth, Alignment::kFirstPose);
  const int delta =
      std::min(options.rpe_delta_frames, std::max(1, report->frames - 1));
  report->rpe_refined = RelativePoseError(map.trajectory, d.groundtruth, delta);
  report->rpe_odometry = RelativePoseError(d.odometry, d.groundtruth, delta);
  return world_from_map.rigid;
}

}  // namespace

nlohmann::json DemoReport::ToJson() const {
  nlohmann::json j;
  j["paths"] = {{"report_json", report_json.string()},
                {"dataset", dataset_dir.string()},
                {"map", map_dir.string()}};
  // The structure figures under the keys report.json has always had
  // (counts, point_error, planes); the per-true-plane list of the eval
  // JSON is not part of it.
  const nlohmann::json s = monomap::ToJson(structure);
  j["counts"] = s["counts"];
  j["counts"]["frames"] = frames;
  j["counts"]["tracks"] = tracks;
  j["counts"]["landmarks"] = landmarks;
  j["point_error"] = s["point_error"];
  j["planes"] = s["planes"];
  j["trajectory"] = {{"alignment", "first_pose"},
                     {"ate_refined", monomap::ToJson(ate_refined)},
                     {"ate_odometry", monomap::ToJson(ate_odometry)},
                     {"rpe_refined", monomap::ToJson(rpe_refined)},
                     {"rpe_odometry", monomap::ToJson(rpe_odometry)}};
  j["mapping"] = mapping;
  if (!localization.runs.empty()) j["localization"] = localization.ToJson();
  j["timings_seconds"] = {{"simulate", simulate_seconds},
                          {"mapping", mapping_seconds},
                          {"evaluation", evaluation_seconds},
                          {"localization", localization.seconds},
                          {"total", total_seconds}};
  return j;
}

DemoReport RunDemo(const DemoOptions& options) {
  options.Check();
  const Timer total_timer;
  auto say = [&](const std::string& text) {
    if (options.show_progress) std::fprintf(stderr, "demo: %s\n", text.c_str());
  };
  DemoReport report;
  const std::filesystem::path dir = options.output_dir;
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) {
    throw OutputError("cannot create " + dir.string() + ": " + ec.message());
  }
  report.dataset_dir = dir / "dataset";
  report.map_dir = dir / "map";
  report.report_json = dir / "report.json";

  say("simulating " + options.world + " (" +
      std::to_string(options.num_frames) + " frames) -> " +
      report.dataset_dir.string());
  SimulationOptions sim;
  sim.world = options.world;
  sim.seed = options.seed;
  sim.num_frames = options.num_frames;
  sim.width = options.width;
  sim.height = options.height;
  sim.show_progress = options.show_progress;
  report.simulate_seconds = Simulate(sim, report.dataset_dir).seconds;
  DemoDataset data = LoadDemoDataset(report.dataset_dir);
  if (options.given_camera) data.blind.camera = *options.given_camera;

  say("building the map -> " + report.map_dir.string());
  MappingOptions mapping_options = options.mapping;
  mapping_options.show_progress = options.show_progress;
  const Timer mapping_timer;
  const MappingResult result = BuildMap(data.blind, mapping_options);
  WriteMappingResult(report.map_dir, result);
  report.mapping_seconds = mapping_timer.ElapsedSeconds();
  report.mapping = result.report.ToJson();
  report.frames = static_cast<int>(data.blind.frames.size());
  report.tracks = static_cast<int>(result.tracks.size());
  report.landmarks = static_cast<int>(result.map.landmarks.size());

  say("evaluating against the ground truth");
  const Timer eval_timer;
  const Rigid3d world_from_map =
      EvaluateDemoMap(result.map, data, options, &report);
  report.evaluation_seconds = eval_timer.ElapsedSeconds();

  if (options.localization.enabled) {
    say("localizing a second traversal (MCL and MCC, global start)");
    DemoLocalizationOptions localization = options.localization;
    localization.given_camera = options.given_camera;
    report.localization =
        RunDemoLocalization(result.map, sim, world_from_map.Inverse(),
                            localization, dir / "localization_dataset");
  }
  report.total_seconds = total_timer.ElapsedSeconds();
  WriteFileAtomic(report.report_json, report.ToJson().dump(2) + "\n");
  return report;
}

}  // namespace monomap
