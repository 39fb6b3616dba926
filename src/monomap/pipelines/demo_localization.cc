#include "monomap/pipelines/demo_localization.h"

#include <algorithm>
#include <random>

#include "monomap/eval/report_json.h"
#include "monomap/io/dataset.h"
#include "monomap/util/error.h"
#include "monomap/util/progress.h"

namespace monomap {

void DemoLocalizationOptions::Check() const {
  CheckOption(num_frames >= 2, "localization.num_frames", "must be >= 2");
  CheckOption(start_offset_m >= 0, "localization.start_offset_m",
              "must be >= 0");
  CheckOption(particles >= 10, "localization.particles", "must be >= 10");
  CheckOption(plotted_particles >= 1, "localization.plotted_particles",
              "must be >= 1");
  CheckOption(fidelity_stride >= 1, "localization.fidelity_stride",
              "must be >= 1");
  accuracy.Check();
  fidelity.Check();
}

nlohmann::json DemoLocalizationRun::ToJson() const {
  nlohmann::json particles = nlohmann::json::array();
  for (const LocalizerStepStats& s : report.steps) {
    particles.push_back(s.particles);
  }
  return {{"method", name},
          {"accuracy", accuracy.ToJson(true)},
          {"seconds", report.seconds},
          {"mean_step_ms", 1e3 * report.mean_step_seconds},
          {"mean_particles", report.mean_particles},
          {"mcc_accepted", report.mcc_accepted},
          {"particles_per_step", particles}};
}

nlohmann::json DemoLocalization::ToJson() const {
  nlohmann::json runs_json = nlohmann::json::array();
  for (const DemoLocalizationRun& r : runs) runs_json.push_back(r.ToJson());
  return {{"dataset", dataset_dir.string()},
          {"frames", frames},
          {"texture_fidelity", monomap::ToJson(fidelity)},
          {"runs", runs_json},
          {"simulate_seconds", simulate_seconds},
          {"seconds", seconds}};
}

DemoLocalization RunDemoLocalization(const Map& map,
                                     const SimulationOptions& mapping_sim,
                                     const Rigid3d& map_from_world,
                                     const DemoLocalizationOptions& options,
                                     const std::filesystem::path& dataset_dir) {
  options.Check();
  const Timer timer;
  DemoLocalization out;
  out.dataset_dir = dataset_dir;

  // The second traversal: same world and textures, its own errors.
  SimulationOptions sim = mapping_sim;
  sim.num_frames = options.num_frames;
  sim.run_seed = mapping_sim.seed + options.run_seed_offset;
  sim.path.start_offset_m = options.start_offset_m;
  sim.path.lateral_offset_m = options.lateral_offset_m;
  out.simulate_seconds = Simulate(sim, dataset_dir).seconds;
  Dataset live = LoadDataset(dataset_dir);
  if (options.given_camera) live.camera = *options.given_camera;
  out.frames = static_cast<int>(live.frames.size());
  for (const DatasetFrame& f : live.frames) {
    if (!f.groundtruth_world_from_cam) {
      throw StageError("demo: the localization run has no ground truth");
    }
    out.groundtruth.push_back(
        {f.timestamp, map_from_world * *f.groundtruth_world_from_cam});
  }

  // Texture fidelity: the map rendered from poses it was not built from.
  {
    std::vector<Rigid3d> poses;
    std::vector<cv::Mat> images;
    std::vector<int> frames;
    for (int i = 0; i < out.frames; i += options.fidelity_stride) {
      poses.push_back(out.groundtruth[i].world_from_cam);
      images.push_back(live.LoadImage(i));
      frames.push_back(i);
    }
    out.fidelity =
        EvaluateRenderFidelity(map, LensForLocalization(map, live.camera),
                               poses, images, frames, options.fidelity);
  }

  // The localizer never sees the traversal's ground truth.
  live.has_groundtruth = false;
  for (DatasetFrame& f : live.frames) f.groundtruth_world_from_cam.reset();
  for (const LocalizationMethod method :
       {LocalizationMethod::kMcl, LocalizationMethod::kMcc}) {
    LocalizationPipelineOptions po;
    LocalizerOptions& lo = po.localizer;
    lo.method = method;
    lo.state = LocalizationState::kPlanar;
    lo.init.kind = LocalizationInit::kGlobal;
    lo.mcl.SetParticleBudget(options.particles);
    lo.seed = mapping_sim.seed + options.filter_seed_offset;
    DemoLocalizationRun run;
    run.name = method == LocalizationMethod::kMcc ? "MCC" : "MCL";
    std::vector<std::vector<Particle>> sets;
    run.report = LocalizeSequence(map, live, po, &run.trajectory, &sets);
    run.accuracy =
        EvaluateLocalization(run.trajectory, out.groundtruth, options.accuracy);
    std::mt19937_64 rng(mapping_sim.seed);
    for (std::vector<Particle>& set : sets) {
      if (static_cast<int>(set.size()) > options.plotted_particles) {
        std::shuffle(set.begin(), set.end(), rng);
        set.resize(options.plotted_particles);
      }
      std::vector<Eigen::Vector3d> xyz;
      xyz.reserve(set.size());
      for (const Particle& p : set) {
        xyz.push_back(p.world_from_cam.translation);
      }
      run.particles.push_back(std::move(xyz));
    }
    out.runs.push_back(std::move(run));
  }
  out.seconds = timer.ElapsedSeconds();
  return out;
}

}  // namespace monomap
