// monomap eval render MAP_DIR DATASET [--stride N] [--width W]
//     [--min-coverage C] [--wrong-offset M] [--first-frame F --frames N]
//     [--align none|first-pose] [--json OUT.json]
#include <cstdio>
#include <memory>

#include "monomap/eval/render_fidelity.h"
#include "monomap/eval/report_json.h"
#include "monomap/eval/trajectory_metrics.h"
#include "monomap/exe/commands.h"
#include "monomap/exe/eval_commands.h"
#include "monomap/io/dataset.h"
#include "monomap/io/map_format.h"
#include "monomap/util/error.h"

namespace monomap {

namespace {

struct RenderArgs {
  std::string map_dir, dataset, align = "none", json;
  int stride = 5, first_frame = 0, num_frames = -1;
  double wrong_offset_m = 0.05;
  RenderFidelityOptions options;
};

// The dataset's frames to compare: every stride-th, its ground-truth pose
// in the map's frame, its image and its frame number.
struct RenderFrames {
  Camera camera;
  std::vector<Rigid3d> poses;
  std::vector<cv::Mat> images;
  std::vector<int> frames;
};

RenderFrames LoadRenderFrames(const RenderArgs& a, const Map& map) {
  DatasetOptions dataset_options;
  dataset_options.first_frame = a.first_frame;
  dataset_options.num_frames = a.num_frames;
  const Dataset dataset = LoadDataset(a.dataset, dataset_options);
  if (!dataset.has_groundtruth) {
    throw InputError(a.dataset +
                     ": no groundtruth.txt: eval render renders from "
                     "ground-truth poses");
  }
  Rigid3d map_from_truth;
  if (a.align == "first-pose") {
    // The ground truth at the map's first pose may lie before
    // --first-frame: take it from the whole dataset.
    std::vector<TimedPose> truth;
    for (const DatasetFrame& f : LoadDataset(a.dataset).frames) {
      truth.push_back({f.timestamp, *f.groundtruth_world_from_cam});
    }
    map_from_truth =
        AlignTrajectories(truth, map.trajectory, Alignment::kFirstPose).rigid;
  }
  RenderFrames r;
  r.camera = dataset.camera;
  for (size_t i = 0; i < dataset.frames.size();
       i += static_cast<size_t>(a.stride)) {
    r.poses.push_back(map_from_truth *
                      *dataset.frames[i].groundtruth_world_from_cam);
    r.images.push_back(dataset.LoadImage(i));
    r.frames.push_back(a.first_frame + static_cast<int>(i));
  }
  return r;
}

// The same frames from poses moved along the camera's x axis: a line of
// the table, and j["wrong_pose"].
std::string CompareWrongPoses(const RenderArgs& a, const Map& map,
                              const RenderFrames& r, const RenderFidelity& f,
                              nlohmann::json* j) {
  const RenderFidelity w = EvaluateRenderFidelity(
      map, r.camera, MovedAlongCameraX(r.poses, a.wrong_offset_m), r.images,
      r.frames, a.options);
  const PoseDiscrimination d = ComparePoses(f, w);
  (*j)["wrong_pose"] = {{"offset_m", a.wrong_offset_m},
                        {"ncc", ToJson(w.ncc)},
                        {"compared", d.compared},
                        {"true_pose_better", d.TrueBetterShare()}};
  char line[200];
  std::snprintf(line, sizeof(line),
                "poses moved %.3f m along camera x: NCC median %.3f "
                "(true poses %.3f); the true pose matches better in "
                "%d of %d frames\n",
                a.wrong_offset_m, w.ncc.median, f.ncc.median, d.true_better,
                d.compared);
  return line;
}

void RunEvalRender(const RenderArgs& a) {
  const Map map = ReadMap(a.map_dir);
  const RenderFrames r = LoadRenderFrames(a, map);
  const RenderFidelity f = EvaluateRenderFidelity(
      map, r.camera, r.poses, r.images, r.frames, a.options);
  nlohmann::json j = ToJson(f);
  j["alignment"] = a.align;
  j["stride"] = a.stride;
  j["width"] = a.options.width;
  std::string text =
      "texture fidelity (alignment " + a.align + ")\n" + FormatTable(f);
  if (a.wrong_offset_m > 0) text += CompareWrongPoses(a, map, r, f, &j);
  PrintOrWrite(j, text, a.json);
}

void AddRenderOptions(CLI::App* cmd, RenderArgs* a) {
  cmd->add_option("--stride", a->stride, "Compare every n-th frame")
      ->check(CLI::Range(1, 1000000))
      ->capture_default_str();
  cmd->add_option("--width", a->options.width,
                  "Compare at this width (0: the camera's)")
      ->capture_default_str();
  cmd->add_option("--min-coverage", a->options.min_coverage,
                  "Skip frames whose render covers less of the image")
      ->capture_default_str();
  AddFrameRangeOptions(cmd, &a->first_frame, &a->num_frames);
  cmd->add_option("--align", a->align,
                  "none: the map is in the ground truth's frame; "
                  "first-pose: align the map's first trajectory pose with "
                  "the dataset's ground truth at that time (same run)")
      ->check(CLI::IsMember({"none", "first-pose"}))
      ->capture_default_str();
  cmd->add_option("--wrong-offset", a->wrong_offset_m,
                  "Also compare renders from the true poses moved this far "
                  "(m) along the camera's x axis: how much better the true "
                  "pose matches (0: skip)")
      ->check(CLI::Range(0.0, 1e3))
      ->capture_default_str();
  cmd->add_option("--json", a->json, "Write the figures as JSON");
}

}  // namespace

void RegisterEvalRenderCommand(CLI::App* eval) {
  auto a = std::make_shared<RenderArgs>();
  CLI::App* cmd = eval->add_subcommand(
      "render",
      "Texture fidelity: render the map from a dataset's ground-truth poses "
      "and compare with its images (NCC, gain-compensated PSNR)");
  cmd->add_option("map", a->map_dir, "Map directory")->required();
  cmd->add_option("dataset", a->dataset,
                  "Dataset with groundtruth.txt (best: frames the map was "
                  "not built from)")
      ->required();
  AddRenderOptions(cmd, a.get());
  cmd->callback([a]() { RunEvalRender(*a); });
}

}  // namespace monomap
