// monomap eval checkerboard MAP_DIR --structure STRUCTURE.yaml
//     [--json OUT.json]
#include <memory>

#include "monomap/eval/checkerboard_accuracy.h"
#include "monomap/eval/report_json.h"
#include "monomap/exe/eval_commands.h"
#include "monomap/io/map_format.h"
#include "monomap/util/error.h"

namespace monomap {

void RegisterEvalCheckerboardCommand(CLI::App* eval) {
  struct Args {
    std::string map_dir, structure, json;
  };
  auto a = std::make_shared<Args>();
  CLI::App* cmd = eval->add_subcommand(
      "checkerboard",
      "Find a known checkerboard in the plane textures and compare its "
      "corners, mapped to 3D, with their true positions");
  cmd->add_option("map", a->map_dir, "Map directory")->required();
  cmd->add_option("--structure", a->structure,
                  "Ground-truth structure YAML with a 'chessboard' entry")
      ->required();
  cmd->add_option("--json", a->json, "Write the figures as JSON");
  cmd->callback([a]() {
    const Map map = ReadMap(a->map_dir);
    const CheckerboardSpec spec = ReadCheckerboardYaml(a->structure);
    const CheckerboardAccuracy acc = EvaluateCheckerboard(map, spec);
    PrintOrWrite(ToJson(acc, spec), FormatTable(acc, spec), a->json);
    if (!acc.found) throw StageError("checkerboard not found in any texture");
  });
}

}  // namespace monomap
