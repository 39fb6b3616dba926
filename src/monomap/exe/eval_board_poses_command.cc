// monomap eval board-poses DATASET --structure STRUCTURE.yaml -o REF.txt
//     [--camera CAMERA.yaml] [--anchor TRAJ.txt] [--first-frame F --frames N]
//     [--max-rms PX] [--json OUT.json]
#include <memory>

#include "monomap/eval/board_poses.h"
#include "monomap/eval/report_json.h"
#include "monomap/exe/commands.h"
#include "monomap/exe/eval_commands.h"
#include "monomap/io/dataset.h"
#include "monomap/io/trajectory_io.h"
#include "monomap/util/error.h"

namespace monomap {

namespace {

struct BoardPoseArgs {
  std::string dataset, structure, output, json, camera_yaml, anchor;
  int first_frame = 0, num_frames = -1;
  BoardPoseOptions options;
};

BoardPoseReport EstimateDatasetBoardPoses(const BoardPoseArgs& a) {
  DatasetOptions dataset_options;
  dataset_options.load_groundtruth = false;
  dataset_options.camera_yaml = a.camera_yaml;
  dataset_options.first_frame = a.first_frame;
  dataset_options.num_frames = a.num_frames;
  const Dataset dataset = LoadDataset(a.dataset, dataset_options);
  const CheckerboardSpec spec = ReadCheckerboardYaml(a.structure);
  std::vector<double> timestamps;
  std::vector<Rigid3d> hints;  // odometry: tells the board's half turns apart
  for (const DatasetFrame& f : dataset.frames) {
    timestamps.push_back(f.timestamp);
    hints.push_back(f.odometry_world_from_cam);
  }
  return EstimateBoardPoses(
      [&](int i) { return dataset.LoadImage(static_cast<size_t>(i)); },
      timestamps, hints, dataset.camera, spec, a.options);
}

void RunEvalBoardPoses(const BoardPoseArgs& a) {
  const BoardPoseReport report = EstimateDatasetBoardPoses(a);
  if (report.poses.empty()) {
    throw StageError(a.dataset + ": the checkerboard was found in no frame");
  }
  std::vector<TimedPose> poses = report.poses;
  if (!a.anchor.empty()) {
    Rigid3d anchor_pose;
    if (!InterpolatePose(ReadTumTrajectory(a.anchor), poses[0].timestamp, 0.1,
                         &anchor_pose)) {
      throw InputError(a.anchor, "timestamps",
                       "no pose at the first board frame's time " +
                           std::to_string(poses[0].timestamp));
    }
    ExpressInAnchorFrame(anchor_pose, &poses);
  }
  WriteTumTrajectory(a.output, poses,
                     "camera poses from checkerboard PnP (monomap eval "
                     "board-poses)");
  const std::string header =
      "board poses: " + std::to_string(report.poses.size()) + " of " +
      std::to_string(report.frames) + " frames -> " + a.output + "\n";
  PrintOrWrite(ToJson(report), header + FormatTable(report), a.json);
}

}  // namespace

void RegisterEvalBoardPosesCommand(CLI::App* eval) {
  auto a = std::make_shared<BoardPoseArgs>();
  CLI::App* cmd = eval->add_subcommand(
      "board-poses",
      "A reference trajectory from the images: the camera pose of every "
      "frame that shows the known checkerboard (PnP on its corners)");
  cmd->add_option("dataset", a->dataset, "Dataset directory")->required();
  cmd->add_option("--structure", a->structure,
                  "Ground-truth structure YAML with a 'chessboard' entry")
      ->required();
  cmd->add_option("-o,--output", a->output,
                  "Reference trajectory to write (TUM, world_from_cam)")
      ->required();
  cmd->add_option("--max-rms", a->options.max_rms_px,
                  "Refuse poses whose corner RMS error exceeds this (px)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--camera", a->camera_yaml,
                  "Calibration to use instead of DATASET/camera.yaml "
                  "(e.g. from 'monomap calibrate')");
  cmd->add_option(
      "--anchor", a->anchor,
      "Express the poses in this trajectory's frame (TUM), tied at the first "
      "frame with a pose: e.g. the odometry a map was built in");
  AddFrameRangeOptions(cmd, &a->first_frame, &a->num_frames);
  cmd->add_option("--json", a->json, "Write the figures as JSON");
  cmd->callback([a]() { RunEvalBoardPoses(*a); });
}

}  // namespace monomap
