// monomap eval lens MAP_DIR [--trajectory REF.txt] [--centre-radius PX]
//     [--json OUT.json]
#include <filesystem>
#include <memory>

#include "monomap/eval/lens_residuals.h"
#include "monomap/eval/report_json.h"
#include "monomap/exe/eval_commands.h"
#include "monomap/io/feature_table.h"
#include "monomap/io/map_format.h"
#include "monomap/io/trajectory_io.h"
#include "monomap/util/error.h"

namespace monomap {

namespace {

struct LensArgs {
  std::string map_dir, trajectory, json;
  LensResidualOptions options;
};

// The poses to trust at the map's frames: the map's own, or those of
// `trajectory_path` (TUM) at the map's frame times.
std::vector<Rigid3d> TrustedPoses(const Map& map,
                                  const std::string& trajectory_path) {
  std::vector<Rigid3d> world_from_cam;
  if (trajectory_path.empty()) {
    for (const TimedPose& p : map.trajectory) {
      world_from_cam.push_back(p.world_from_cam);
    }
    return world_from_cam;
  }
  const auto reference = ReadTumTrajectory(trajectory_path);
  for (const TimedPose& p : map.trajectory) {
    Rigid3d pose;
    if (!InterpolatePose(reference, p.timestamp, 0.1, &pose)) {
      throw InputError(
          trajectory_path, "timestamps",
          "no pose at the map's frame time " + std::to_string(p.timestamp));
    }
    world_from_cam.push_back(pose);
  }
  return world_from_cam;
}

void RunEvalLens(const LensArgs& a) {
  const Map map = ReadMap(a.map_dir);
  const auto tracks =
      ReadFeatureTable(std::filesystem::path(a.map_dir) / "features.csv");
  const std::vector<Rigid3d> world_from_cam = TrustedPoses(map, a.trajectory);
  const LensResidualReport report =
      EvaluateLensResiduals(map.camera, world_from_cam, tracks, a.options);
  PrintOrWrite(ToJson(report), FormatTable(report), a.json);
}

}  // namespace

void RegisterEvalLensCommand(CLI::App* eval) {
  auto a = std::make_shared<LensArgs>();
  CLI::App* cmd = eval->add_subcommand(
      "lens",
      "Check the lens calibration at the rim: residuals of the map's tracks, "
      "fixed by their central observations, by distance from the centre");
  cmd->add_option("map", a->map_dir, "Map directory (with features.csv)")
      ->required();
  cmd->add_option("--trajectory", a->trajectory,
                  "Poses to trust (TUM), e.g. from 'eval board-poses'; "
                  "default: the map's own");
  cmd->add_option("--centre-radius", a->options.centre_radius_px,
                  "Observations within this radius (px) fix the points")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--json", a->json, "Write the figures as JSON");
  cmd->callback([a]() { RunEvalLens(*a); });
}

}  // namespace monomap
