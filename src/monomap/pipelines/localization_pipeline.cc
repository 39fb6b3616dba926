#include "monomap/pipelines/localization_pipeline.h"

#include <cmath>

#include "monomap/io/map_format.h"
#include "monomap/pipelines/mapping_pipeline.h"
#include "monomap/util/error.h"
#include "monomap/util/progress.h"

namespace monomap {

void LocalizationPipelineOptions::Check() const {
  localizer.Check();
  CheckOption(within_m > 0, "within_m", "must be > 0");
}

nlohmann::json LocalizationReport::ToJson() const {
  nlohmann::json j;
  j["frames"] = frames;
  j["seconds"] = seconds;
  j["mean_step_seconds"] = mean_step_seconds;
  j["mean_particles"] = mean_particles;
  j["mcc_accepted"] = mcc_accepted;
  j["map_lens"] = map_lens;
  if (has_errors) {
    j["rmse_translation_m"] = rmse_translation_m;
    j["mean_rotation_error_deg"] = mean_rotation_error_deg;
    j["final_translation_error_m"] = final_translation_error_m;
    j["final_rotation_error_deg"] = final_rotation_error_deg;
    j["fraction_within_10cm"] = fraction_within_10cm;
    for (const auto& [key, v] : {std::pair{"mean_translation_error_rigid_m",
                                           mean_translation_error_rigid_m},
                                 std::pair{"mean_rotation_error_rigid_deg",
                                           mean_rotation_error_rigid_deg}}) {
      j[key] = std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
    }
  }
  nlohmann::json steps_json = nlohmann::json::array();
  for (const LocalizerStepStats& s : steps) {
    steps_json.push_back({{"particles", s.particles},
                          {"ess", s.ess},
                          {"best_ncc", s.best_ncc},
                          {"best_coverage", s.best_coverage},
                          {"mcc_accepted", s.mcc_accepted},
                          {"merged", s.merged},
                          {"injected", s.injected},
                          {"relocalizing", s.relocalizing},
                          {"particles_weighed", s.particles_weighed},
                          {"refined", s.refined},
                          {"weigh_seconds", s.weigh_seconds},
                          {"mcc_seconds", s.mcc_seconds},
                          {"seconds", s.seconds},
                          {"cpu_seconds", s.cpu_seconds}});
  }
  j["steps"] = steps_json;
  return j;
}

namespace {

// The planar state needs 2D odometry for every frame and the camera mount
// (checked in this order: the mount is read only along with the odometry).
void CheckDatasetForState(const Dataset& dataset, LocalizationState state) {
  if (state != LocalizationState::kPlanar) return;
  for (const DatasetFrame& f : dataset.frames) {
    if (!f.odometry_base) {
      throw InputError(dataset.root.string(), "odometry2d.txt",
                       "the planar state needs 2D odometry for every frame "
                       "(or use --state 6dof)");
    }
  }
  if (!dataset.base_from_cam) {
    throw InputError(dataset.root.string(), "camera_mount.yaml",
                     "the planar state needs the camera mount");
  }
}

// A dataset frame as a live robot would give it to the session.
SessionFrame FrameOf(const Dataset& dataset, size_t i) {
  const DatasetFrame& f = dataset.frames[i];
  SessionFrame frame;
  frame.stamp = f.timestamp;
  frame.image = dataset.LoadImage(i);
  frame.odom_from_cam = f.odometry_world_from_cam;
  frame.odom_base = f.odometry_base;
  return frame;
}

// The errors of the estimates against the frames' ground truth, computed
// by eval; nothing if no frame has ground truth.
void AddErrors(const Dataset& dataset, const std::vector<TimedPose>& estimate,
               double within_m, LocalizationReport* report) {
  std::vector<TimedPose> groundtruth;
  for (const DatasetFrame& f : dataset.frames) {
    if (f.groundtruth_world_from_cam) {
      groundtruth.push_back({f.timestamp, *f.groundtruth_world_from_cam});
    }
  }
  if (groundtruth.empty()) return;
  const LocalizationAccuracy a = EvaluateLocalization(estimate, groundtruth);
  double sum_sq = 0.0;
  int within = 0;
  for (const double e : a.translation_error_m) {
    sum_sq += e * e;
    within += e < within_m ? 1 : 0;
  }
  report->has_errors = true;
  report->rmse_translation_m = std::sqrt(sum_sq / a.matched);
  report->mean_rotation_error_deg = a.mean_rotation_error_all_deg;
  report->final_translation_error_m = a.final_translation_error_m;
  report->final_rotation_error_deg = a.final_rotation_error_deg;
  report->fraction_within_10cm = static_cast<double>(within) / a.matched;
  report->mean_translation_error_rigid_m = a.mean_translation_error_rigid_m;
  report->mean_rotation_error_rigid_deg = a.mean_rotation_error_rigid_deg;
}

}  // namespace

Camera LensForLocalization(const Map& map, const Camera& live, bool* from_map) {
  const bool use_map =
      map.given_camera && SameCalibration(*map.given_camera, live);
  if (from_map) *from_map = use_map;
  return use_map ? map.camera : live;
}

LocalizationReport LocalizeSequence(
    const Map& map, const Dataset& dataset,
    const LocalizationPipelineOptions& options,
    std::vector<TimedPose>* trajectory,
    std::vector<std::vector<Particle>>* particle_sets) {
  options.Check();
  if (dataset.frames.empty()) throw InputError("localization: no frames");
  CheckDatasetForState(dataset, options.localizer.state);
  const Timer timer;
  // The session is what a live robot runs; the caller keeps `map` alive.
  SessionOptions session_options;
  session_options.localizer = options.localizer;
  session_options.output_particles = particle_sets != nullptr;
  LocalizationReport report;
  LocalizationSession session(
      std::shared_ptr<const Map>(&map, [](const Map*) {}),
      LensForLocalization(map, dataset.camera, &report.map_lens),
      session_options, dataset.base_from_cam);

  std::vector<TimedPose> estimate;
  if (particle_sets) particle_sets->clear();
  ProgressBar progress("localize", dataset.frames.size(),
                       options.show_progress);
  for (size_t i = 0; i < dataset.frames.size(); ++i) {
    SessionResult r = session.Process(FrameOf(dataset, i));
    estimate.push_back({r.stamp, r.world_from_cam});
    if (particle_sets) particle_sets->push_back(std::move(r.particles));
    report.steps.push_back(r.stats);
    report.mean_step_seconds += r.stats.seconds;
    report.mean_particles += r.stats.particles;
    report.mcc_accepted += r.stats.mcc_accepted;
    progress.Advance();
  }
  progress.Finish();
  report.frames = static_cast<int>(dataset.frames.size());
  report.mean_step_seconds /= report.frames;
  report.mean_particles /= report.frames;
  AddErrors(dataset, estimate, options.within_m, &report);
  if (trajectory) *trajectory = std::move(estimate);
  report.seconds = timer.ElapsedSeconds();
  return report;
}

std::unique_ptr<LocalizationSession> OpenLocalizationSession(
    const std::filesystem::path& map_dir, const SessionOptions& options,
    const std::optional<Camera>& live_camera,
    const std::optional<Rigid3d>& base_from_cam) {
  auto map = std::make_shared<const Map>(ReadMap(map_dir));
  const Camera camera =
      live_camera ? LensForLocalization(*map, *live_camera) : map->camera;
  return std::make_unique<LocalizationSession>(std::move(map), camera, options,
                                               base_from_cam);
}

}  // namespace monomap
