// monomap eval planes MAP_DIR (--plane STRUCTURE.yaml | --surface CLOUD.ply)
//     [--spacing M] [--json OUT.json]
#include <memory>

#include "monomap/eval/plane_accuracy.h"
#include "monomap/eval/report_json.h"
#include "monomap/exe/eval_commands.h"
#include "monomap/io/map_format.h"
#include "monomap/io/ply.h"
#include "monomap/util/error.h"

namespace monomap {

namespace {

struct PlaneArgs {
  std::string map_dir, surface_ply, plane_yaml, json;
  double spacing_m = 0.01;
};

void RunEvalPlanes(const PlaneArgs& a) {
  if (a.plane_yaml.empty() == a.surface_ply.empty()) {
    throw OptionsError("eval planes: give exactly one of --plane or --surface");
  }
  const Map map = ReadMap(a.map_dir);
  PlaneSurfaceAccuracy acc;
  if (!a.surface_ply.empty()) {
    const NearestNeighborIndex index(ReadPlyPoints(a.surface_ply));
    acc = EvaluatePlaneSurfaces(
        map, a.spacing_m,
        [&](const Eigen::Vector3d& x) { return index.NearestDistance(x); });
  } else {
    const Plane truth = ReadGroundTruthPlaneYaml(a.plane_yaml);
    acc =
        EvaluatePlaneSurfaces(map, a.spacing_m, [&](const Eigen::Vector3d& x) {
          return std::abs(truth.SignedDistance(x));
        });
  }
  PrintOrWrite(ToJson(acc), FormatTable(acc), a.json);
}

}  // namespace

void RegisterEvalPlanesCommand(CLI::App* eval) {
  auto a = std::make_shared<PlaneArgs>();
  CLI::App* cmd = eval->add_subcommand(
      "planes",
      "Distance of samples of each textured plane (its seen texels) to the "
      "true surface");
  cmd->add_option("map", a->map_dir, "Map directory")->required();
  auto* surface =
      cmd->add_option("--surface", a->surface_ply, "Ground-truth PLY");
  auto* plane = cmd->add_option("--plane", a->plane_yaml,
                                "Ground-truth structure YAML (plane)");
  surface->excludes(plane);
  cmd->add_option("--spacing", a->spacing_m, "Sample spacing (m)")
      ->capture_default_str();
  cmd->add_option("--json", a->json, "Write the figures as JSON");
  cmd->callback([a]() { RunEvalPlanes(*a); });
}

}  // namespace monomap
