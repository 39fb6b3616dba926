// monomap eval structure MAP_DIR --structure STRUCTURE_DIR
//     [--align none|first-pose|se3|sim3|sim3-poses --groundtruth GT.txt]
//     [--json OUT.json]
#include <cstdio>
#include <filesystem>
#include <memory>

#include "monomap/eval/report_json.h"
#include "monomap/eval/structure_accuracy.h"
#include "monomap/eval/trajectory_metrics.h"
#include "monomap/exe/eval_commands.h"
#include "monomap/io/feature_table.h"
#include "monomap/io/map_format.h"
#include "monomap/util/error.h"

namespace monomap {

namespace {

struct StructureArgs {
  std::string map_dir, structure_dir, json;
  AlignmentArgs alignment;
  StructureAccuracyOptions options;  // the project's matching thresholds
};

// Relative point errors divide by each landmark's mean depth, which
// points.ply does not hold: recompute it from the feature table. Returns
// false (depth: distance to the nearest camera) if the map has none.
bool SetDepthsFromFeatures(const std::string& map_dir, Map* map) {
  const std::filesystem::path features =
      std::filesystem::path(map_dir) / "features.csv";
  std::error_code ec;  // a loop or a FIFO: no features, not a throw
  const bool have_features = std::filesystem::is_regular_file(features, ec);
  if (!have_features) {
    std::fprintf(stderr,
                 "monomap: note: %s missing: relative point errors use "
                 "the distance to the nearest camera\n",
                 features.string().c_str());
  }
  SetLandmarkDepths(
      have_features ? ReadFeatureTable(features) : std::vector<Track>(), map);
  return have_features;
}

void RunEvalStructure(const StructureArgs& a) {
  Map map = ReadMap(a.map_dir);
  const Sim3d truth_from_map =
      TruthFromMap("eval structure", a.alignment, map.trajectory);
  const Map truth = ReadMap(a.structure_dir);
  const bool have_features = SetDepthsFromFeatures(a.map_dir, &map);
  // gt ~ scale * R * x + t: scale the map, then move it rigidly.
  if (truth_from_map.scale != 1.0) {
    map = ScaledMap(map, truth_from_map.scale);
  }
  const StructureAccuracy acc =
      EvaluateStructure(map, truth, truth_from_map.rigid, a.options);
  nlohmann::json j = ToJson(acc);
  j["alignment"] = a.alignment.align;
  j["alignment_scale"] = truth_from_map.scale;
  j["relative_error_depth"] = have_features
                                  ? "mean_distance_to_observing_cameras"
                                  : "distance_to_nearest_camera";
  j["options"] = ToJson(a.options);
  PrintOrWrite(j,
               "structure accuracy (alignment " + a.alignment.align + ")\n" +
                   FormatTable(acc),
               a.json);
}

}  // namespace

void RegisterEvalStructureCommand(CLI::App* eval) {
  auto a = std::make_shared<StructureArgs>();
  CLI::App* cmd = eval->add_subcommand(
      "structure",
      "Compare the map with a world's true planes (a simulated dataset's "
      "structure/ directory): point errors, plane matches, precision and "
      "recall");
  cmd->add_option("map", a->map_dir, "Map directory")->required();
  cmd->add_option("--structure", a->structure_dir,
                  "Ground-truth structure as a map directory (the "
                  "simulator writes DATASET/structure)")
      ->required();
  AddAlignmentOptions(cmd, &a->alignment);
  cmd->add_option("--json", a->json, "Write the figures as JSON");
  cmd->callback([a]() { RunEvalStructure(*a); });
}

}  // namespace monomap
