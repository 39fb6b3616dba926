// monomap eval trajectory ESTIMATE.txt GROUNDTRUTH.txt
//     [--align none|first|se3|sim3|sim3-poses] [--delta N] [--json OUT.json]
#include <memory>

#include "monomap/eval/report_json.h"
#include "monomap/eval/trajectory_metrics.h"
#include "monomap/exe/eval_commands.h"
#include "monomap/io/trajectory_io.h"

namespace monomap {

void RegisterEvalTrajectoryCommand(CLI::App* eval) {
  struct Args {
    std::string estimate, groundtruth, align = "se3", json;
    int delta = 1;
  };
  auto a = std::make_shared<Args>();
  CLI::App* cmd = eval->add_subcommand(
      "trajectory", "Absolute and relative pose error of a TUM trajectory");
  cmd->add_option("estimate", a->estimate, "Estimated trajectory (TUM)")
      ->required();
  cmd->add_option("groundtruth", a->groundtruth,
                  "Ground-truth trajectory (TUM)")
      ->required();
  cmd->add_option("--align", a->align,
                  "none | first | se3 | sim3 | sim3-poses (the similarity "
                  "with its rotation from the orientations) | se3-poses "
                  "(the same without scale: one rigid offset removed)")
      ->check(CLI::IsMember(
          {"none", "first", "se3", "sim3", "sim3-poses", "se3-poses"}))
      ->capture_default_str();
  cmd->add_option("--delta", a->delta, "Frame delta of the relative error")
      ->capture_default_str();
  cmd->add_option("--json", a->json, "Write the figures as JSON");
  cmd->callback([a]() {
    const auto est = ReadTumTrajectory(a->estimate);
    const auto gt = ReadTumTrajectory(a->groundtruth);
    const TrajectoryErrors ate =
        AbsoluteTrajectoryError(est, gt, ParseAlignment(a->align), 1e-3);
    const TrajectoryErrors rpe = RelativePoseError(est, gt, a->delta, 1e-3);
    nlohmann::json j;
    j["alignment"] = a->align;
    j["ate"] = ToJson(ate);
    j["rpe"] = ToJson(rpe);
    j["rpe"]["delta_frames"] = a->delta;
    PrintOrWrite(j,
                 "absolute trajectory error (" + a->align + ")\n" +
                     FormatTable(ate) + "relative pose error (delta " +
                     std::to_string(a->delta) + ")\n" + FormatTable(rpe),
                 a->json);
  });
}

}  // namespace monomap
