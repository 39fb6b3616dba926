// monomap eval checkerboard MAP_DIR --structure STRUCTURE.yaml
//     [--align none|first-pose|se3|sim3|sim3-poses --groundtruth GT.txt]
//     [--json OUT.json]
#include <memory>

#include "monomap/eval/checkerboard_accuracy.h"
#include "monomap/eval/report_json.h"
#include "monomap/eval/trajectory_metrics.h"
#include "monomap/exe/eval_commands.h"
#include "monomap/io/map_format.h"
#include "monomap/io/trajectory_io.h"
#include "monomap/util/error.h"

namespace monomap {

namespace {

struct CheckerboardArgs {
  std::string map_dir, structure, json;
  std::string align = "none", groundtruth;
};

void RunEvalCheckerboard(const CheckerboardArgs& a) {
  if ((a.align != "none") != !a.groundtruth.empty()) {
    throw OptionsError(
        "eval checkerboard: --align and --groundtruth go together");
  }
  const Map map = ReadMap(a.map_dir);
  const CheckerboardSpec spec = ReadCheckerboardYaml(a.structure);
  Sim3d truth_from_map;
  if (a.align != "none") {
    truth_from_map = AlignTrajectories(
        map.trajectory, ReadTumTrajectory(a.groundtruth),
        ParseAlignment(a.align == "first-pose" ? "first" : a.align));
  }
  const CheckerboardAccuracy acc =
      EvaluateCheckerboard(map, spec, truth_from_map);
  nlohmann::json j = ToJson(acc, spec);
  j["alignment"] = a.align;
  PrintOrWrite(j, FormatTable(acc, spec), a.json);
  if (!acc.found) throw StageError("checkerboard not found in any texture");
}

}  // namespace

void RegisterEvalCheckerboardCommand(CLI::App* eval) {
  auto a = std::make_shared<CheckerboardArgs>();
  CLI::App* cmd = eval->add_subcommand(
      "checkerboard",
      "Find a known checkerboard in the plane textures and compare its "
      "corners, mapped to 3D, with their true positions");
  cmd->add_option("map", a->map_dir, "Map directory")->required();
  cmd->add_option("--structure", a->structure,
                  "Ground-truth structure YAML with a 'chessboard' entry")
      ->required();
  cmd->add_option("--align", a->align,
                  "Move the corners into the ground truth's frame first: "
                  "none, first-pose, se3, sim3 or sim3-poses (the map's "
                  "trajectory aligned to --groundtruth)")
      ->capture_default_str();
  cmd->add_option("--groundtruth", a->groundtruth,
                  "Ground-truth trajectory (TUM) for --align");
  cmd->add_option("--json", a->json, "Write the figures as JSON");
  cmd->callback([a]() { RunEvalCheckerboard(*a); });
}

}  // namespace monomap
