// The `monomap eval` subcommands, one file each (eval_*_command.cc);
// RegisterEvalCommand (eval_command.cc) adds them under `eval`. The figures
// are computed and formatted in the library (eval/); a command reads its
// inputs, calls it and prints.
#pragma once

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <string>

namespace monomap {

void RegisterEvalPointsCommand(CLI::App* eval);
void RegisterEvalPlanesCommand(CLI::App* eval);
void RegisterEvalCheckerboardCommand(CLI::App* eval);
void RegisterEvalBoardPosesCommand(CLI::App* eval);
void RegisterEvalLensCommand(CLI::App* eval);
void RegisterEvalStructureCommand(CLI::App* eval);
void RegisterEvalRenderCommand(CLI::App* eval);
void RegisterEvalTrajectoryCommand(CLI::App* eval);

// Prints `table` to stdout and, if `json_path` is not empty, writes `j`
// there (atomically).
void PrintOrWrite(const nlohmann::json& j, const std::string& table,
                  const std::string& json_path);

}  // namespace monomap
