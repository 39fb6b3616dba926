// monomap eval checkerboard MAP_DIR --structure STRUCTURE.yaml
//     [--align none|first-pose|se3|sim3|sim3-poses --groundtruth GT.txt]
//     [--json OUT.json]
#include <memory>

#include "monomap/eval/checkerboard_accuracy.h"
#include "monomap/eval/report_json.h"
#include "monomap/exe/eval_commands.h"
#include "monomap/io/map_format.h"
#include "monomap/util/error.h"

namespace monomap {

namespace {

struct CheckerboardArgs {
  std::string map_dir, structure, json;
  AlignmentArgs alignment;
};

void RunEvalCheckerboard(const CheckerboardArgs& a) {
  const Map map = ReadMap(a.map_dir);
  const Sim3d truth_from_map =
      TruthFromMap("eval checkerboard", a.alignment, map.trajectory);
  const CheckerboardSpec spec = ReadCheckerboardYaml(a.structure);
  const CheckerboardAccuracy acc =
      EvaluateCheckerboard(map, spec, truth_from_map);
  nlohmann::json j = ToJson(acc, spec);
  j["alignment"] = a.alignment.align;
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
  AddAlignmentOptions(cmd, &a->alignment);
  cmd->add_option("--json", a->json, "Write the figures as JSON");
  cmd->callback([a]() { RunEvalCheckerboard(*a); });
}

}  // namespace monomap
