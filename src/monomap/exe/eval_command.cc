// monomap eval SUBCOMMAND ...: accuracy figures (one file per subcommand).
#include <iostream>

#include "monomap/exe/commands.h"
#include "monomap/exe/eval_commands.h"
#include "monomap/util/file.h"

namespace monomap {

void PrintOrWrite(const nlohmann::json& j, const std::string& table,
                  const std::string& json_path) {
  std::cout << table;
  if (!json_path.empty()) WriteFileAtomic(json_path, j.dump(2) + "\n");
}

void RegisterEvalCommand(CLI::App& app) {
  CLI::App* eval = app.add_subcommand("eval", "Accuracy figures");
  eval->require_subcommand(1);
  RegisterEvalPointsCommand(eval);
  RegisterEvalPlanesCommand(eval);
  RegisterEvalCheckerboardCommand(eval);
  RegisterEvalBoardPosesCommand(eval);
  RegisterEvalLensCommand(eval);
  RegisterEvalStructureCommand(eval);
  RegisterEvalRenderCommand(eval);
  RegisterEvalTrajectoryCommand(eval);
}

}  // namespace monomap
