// monomap eval points MAP_DIR (--plane STRUCTURE.yaml | --surface CLOUD.ply)
//     [--plane-label L | --largest-plane] [--json OUT.json]
#include <memory>

#include "monomap/eval/point_accuracy.h"
#include "monomap/eval/report_json.h"
#include "monomap/exe/eval_commands.h"
#include "monomap/io/map_format.h"
#include "monomap/io/ply.h"
#include "monomap/util/error.h"

namespace monomap {

namespace {

struct PointArgs {
  std::string map_dir, plane_yaml, surface_ply, json;
  int plane_label = kAllLandmarks;  // -1: points on no plane
  bool largest_plane = false;
};

void RunEvalPoints(const PointArgs& a) {
  if (a.plane_yaml.empty() == a.surface_ply.empty()) {
    throw OptionsError("eval points: give exactly one of --plane or --surface");
  }
  const Map map = ReadMap(a.map_dir);
  int label = a.plane_label;
  if (a.largest_plane) {
    const std::optional<int> largest = LargestPlaneLabel(map);
    if (!largest) throw StageError(a.map_dir + ": map has no plane labels");
    label = *largest;
  }
  const std::vector<Eigen::Vector3d> xs = LandmarkPositions(map, label);
  if (xs.empty()) throw StageError("no points to evaluate");
  const auto dist = DistanceToTrajectory(xs, map.trajectory);
  PointAccuracy acc;
  if (!a.plane_yaml.empty()) {
    acc = EvaluatePointsAgainstPlane(xs, dist,
                                     ReadGroundTruthPlaneYaml(a.plane_yaml));
  } else {
    const NearestNeighborIndex index(ReadPlyPoints(a.surface_ply));
    acc = EvaluatePointsAgainstCloud(xs, dist, index);
  }
  nlohmann::json j = ToJson(acc);
  j["plane_label"] = label;
  PrintOrWrite(j, FormatTable(acc), a.json);
}

}  // namespace

void RegisterEvalPointsCommand(CLI::App* eval) {
  auto a = std::make_shared<PointArgs>();
  CLI::App* cmd = eval->add_subcommand(
      "points", "Point error against a ground-truth plane or surface cloud");
  cmd->add_option("map", a->map_dir, "Map directory")->required();
  auto* plane_opt = cmd->add_option("--plane", a->plane_yaml,
                                    "Ground-truth structure YAML (plane)");
  auto* surface_opt =
      cmd->add_option("--surface", a->surface_ply, "Ground-truth surface PLY");
  plane_opt->excludes(surface_opt);
  cmd->add_option("--plane-label", a->plane_label,
                  "Evaluate only points with this plane label");
  cmd->add_flag("--largest-plane", a->largest_plane,
                "Evaluate only points of the plane with most points");
  cmd->add_option("--json", a->json, "Write the figures as JSON");
  cmd->callback([a]() { RunEvalPoints(*a); });
}

}  // namespace monomap
