// monomap eval SUBCOMMAND ...: accuracy figures (one file per subcommand).
#include <iostream>

#include "monomap/exe/commands.h"
#include "monomap/exe/eval_commands.h"
#include "monomap/io/trajectory_io.h"
#include "monomap/util/error.h"
#include "monomap/util/file.h"

namespace monomap {

void PrintOrWrite(const nlohmann::json& j, const std::string& table,
                  const std::string& json_path) {
  std::cout << table;
  if (!json_path.empty()) WriteFileAtomic(json_path, j.dump(2) + "\n");
}

void AddAlignmentOptions(CLI::App* cmd, AlignmentArgs* a) {
  cmd->add_option("--align", a->align,
                  "none: the map is in the truth's frame (the simulator's "
                  "odometry starts at the true pose); first-pose: align "
                  "the map's first trajectory pose to --groundtruth; "
                  "se3 / sim3: the rigid / similarity transform that best "
                  "fits the map's trajectory positions to --groundtruth "
                  "(sim3 removes the scale error the odometry gives the "
                  "map); sim3-poses: the similarity with its rotation from "
                  "the trajectory's orientations (determined also for a "
                  "straight drive); se3-poses: the same without scale")
      ->check(CLI::IsMember(
          {"none", "first-pose", "se3", "sim3", "sim3-poses", "se3-poses"}))
      ->capture_default_str();
  cmd->add_option("--groundtruth", a->groundtruth,
                  "Ground-truth trajectory (TUM) for --align");
}

Sim3d TruthFromMap(const std::string& command, const AlignmentArgs& a,
                   const std::vector<TimedPose>& map_trajectory) {
  const bool aligned = a.align != "none";
  if (aligned && a.groundtruth.empty()) {
    throw OptionsError(command + ": --align " + a.align +
                       " needs --groundtruth");
  }
  if (!aligned && !a.groundtruth.empty()) {
    throw OptionsError(command + ": --groundtruth is only used with --align");
  }
  if (!aligned) return Sim3d{};
  return AlignTrajectories(
      map_trajectory, ReadTumTrajectory(a.groundtruth),
      ParseAlignment(a.align == "first-pose" ? "first" : a.align));
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
