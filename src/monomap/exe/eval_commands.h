// The `monomap eval` subcommands, one file each (eval_*_command.cc);
// RegisterEvalCommand (eval_command.cc) adds them under `eval`. The figures
// are computed and formatted in the library (eval/); a command reads its
// inputs, calls it and prints.
#pragma once

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "monomap/eval/trajectory_metrics.h"
#include "monomap/map/map.h"

namespace monomap {

void RegisterEvalPointsCommand(CLI::App* eval);
void RegisterEvalPlanesCommand(CLI::App* eval);
void RegisterEvalCheckerboardCommand(CLI::App* eval);
void RegisterEvalBoardPosesCommand(CLI::App* eval);
void RegisterEvalLensCommand(CLI::App* eval);
void RegisterEvalStructureCommand(CLI::App* eval);
void RegisterEvalRenderCommand(CLI::App* eval);
void RegisterEvalTrajectoryCommand(CLI::App* eval);

// The --align / --groundtruth pair of the commands that compare a map with
// a ground truth: a monocular map's frame and scale are its odometry's, so
// the map may first be moved by the transform that best fits its
// trajectory to the true one.
struct AlignmentArgs {
  std::string align = "none";  // none, first-pose, se3, sim3, sim3-poses
  std::string groundtruth;     // the true trajectory (TUM)
};
void AddAlignmentOptions(CLI::App* cmd, AlignmentArgs* a);

// truth_from_map (scale, then rigid) for the map's trajectory: the
// identity for "none". Throws OptionsError naming `command` unless --align
// and --groundtruth are given together.
Sim3d TruthFromMap(const std::string& command, const AlignmentArgs& a,
                   const std::vector<TimedPose>& map_trajectory);

// Prints `table` to stdout and, if `json_path` is not empty, writes `j`
// there (atomically).
void PrintOrWrite(const nlohmann::json& j, const std::string& table,
                  const std::string& json_path);

}  // namespace monomap
