// Map building on the simulated hallway over sequence length and odometry
// quality: what a longer sequence costs and what worse odometry does to
// the map.
//
// Two sweeps, each point one simulated run (world seed --seed) mapped from
// its images and odometry only and compared with the exact ground truth:
//  * frames: the sequence length (at the default odometry noise);
//  * odometry: every error of the odometry model (systematic wheel radius
//    and wheel base errors, random distance and heading noise) scaled by a
//    factor, 1 = the simulator's default (1% scale errors), at --noise-frames.
// Build time is measured in-process around BuildMap (wall and CPU time of
// the process), so simulation and evaluation are not counted.
//
// Prints markdown tables on stdout, writes every figure to --out as JSON.
//
//   build/bench/mapping_sweep --out /tmp/mapping_sweep.json
#include <sys/resource.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "monomap/eval/report_json.h"
#include "monomap/eval/structure_accuracy.h"
#include "monomap/eval/trajectory_metrics.h"
#include "monomap/io/dataset.h"
#include "monomap/io/map_format.h"
#include "monomap/pipelines/mapping_pipeline.h"
#include "monomap/sim/simulate.h"
#include "monomap/util/error.h"
#include "monomap/util/file.h"
#include "monomap/util/progress.h"
#include "monomap/util/runtime.h"
#include "sweep_main.h"

namespace monomap {
namespace {

namespace fs = std::filesystem;

struct SweepOptions {
  std::string world = "hallway";
  uint64_t seed = 1;
  int width = 640;
  int height = 480;
  // Sequence lengths of the frames sweep.
  std::vector<int> frames = {50, 100, 200, 400, 800};
  // Odometry error factors of the noise sweep, and its sequence length.
  std::vector<double> noise = {0.3, 1.0, 2.0, 4.0};
  int noise_frames = 200;
  std::string out = "mapping_sweep.json";
};

double CpuSeconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_utime.tv_sec + u.ru_stime.tv_sec +
         1e-6 * (u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

struct Point {
  int frames = 0;
  double noise = 1.0;
  double path_m = 0.0;
  double odometry_drift_m = 0.0;
  double wall_s = 0.0;
  double cpu_s = 0.0;
  nlohmann::json stage_seconds;
  StructureAccuracy structure;
  TrajectoryErrors ate_refined, ate_odometry;
};

Point RunPoint(const SweepOptions& o, int frames, double noise,
               const fs::path& dir) {
  SimulationOptions sim;
  sim.world = o.world;
  sim.seed = o.seed;
  sim.num_frames = frames;
  sim.width = o.width;
  sim.height = o.height;
  sim.show_progress = false;
  OdometryNoiseOptions& n = sim.odometry;
  n.wheel_radius_error *= noise;
  n.yaw_scale_error *= noise;
  n.translation_noise *= noise;
  n.rotation_noise_per_meter *= noise;
  n.rotation_noise_per_radian *= noise;
  const SimulationReport sr = Simulate(sim, dir);
  const Dataset dataset = LoadDataset(dir);
  std::vector<TimedPose> truth, odometry;
  for (const DatasetFrame& f : dataset.frames) {
    truth.push_back({f.timestamp, *f.groundtruth_world_from_cam});
    odometry.push_back({f.timestamp, f.odometry_world_from_cam});
  }
  Dataset blind = dataset;  // the pipeline never sees ground truth
  blind.has_groundtruth = false;
  for (DatasetFrame& f : blind.frames) f.groundtruth_world_from_cam.reset();

  Point p;
  p.frames = static_cast<int>(dataset.frames.size());
  p.noise = noise;
  p.path_m = sr.path_length_m;
  p.odometry_drift_m = sr.final_drift_m;
  MappingOptions mo;
  mo.show_progress = false;
  const double cpu0 = CpuSeconds();
  const Timer timer;
  const MappingResult result = BuildMap(blind, mo);
  p.wall_s = timer.ElapsedSeconds();
  p.cpu_s = CpuSeconds() - cpu0;
  p.stage_seconds = result.report.ToJson()["timings_seconds"];
  // The simulator's odometry starts at the true pose: no alignment.
  const Map truth_map = ReadMap(dir / "structure");
  p.structure = EvaluateStructure(result.map, truth_map, Rigid3d::Identity(),
                                  StructureAccuracyOptions{});
  p.ate_refined =
      AbsoluteTrajectoryError(result.map.trajectory, truth, Alignment::kNone);
  p.ate_odometry = AbsoluteTrajectoryError(odometry, truth, Alignment::kNone);
  fs::remove_all(dir);
  return p;
}

nlohmann::json ToJson(const Point& p) {
  return {{"frames", p.frames},
          {"odometry_noise_factor", p.noise},
          {"path_length_m", p.path_m},
          {"odometry_final_drift_m", p.odometry_drift_m},
          {"build_wall_seconds", p.wall_s},
          {"build_cpu_seconds", p.cpu_s},
          {"stage_seconds", p.stage_seconds},
          {"structure", monomap::ToJson(p.structure)},
          {"ate_refined", monomap::ToJson(p.ate_refined)},
          {"ate_odometry", monomap::ToJson(p.ate_odometry)}};
}

void PrintRow(const Point& p) {
  const StructureAccuracy& s = p.structure;
  std::printf(
      "| %d | %.1f | %.2f | %.1f | %.1f | %.1f | %.1f | %.1f | %.2f | "
      "%.0f%% / "
      "%.0f%% | %.2f | %.1f | %.1f | %.1f |\n",
      p.frames, p.noise, p.path_m, 100 * p.odometry_drift_m, p.wall_s, p.cpu_s,
      1e3 * p.wall_s / p.frames, p.frames / p.wall_s,
      s.point_error_on_planes.relative_percent.median, 100 * s.recall,
      100 * s.precision, s.normal_error_deg.max, 1e3 * s.offset_error_m.median,
      100 * p.ate_refined.translation_m.rms,
      100 * p.ate_odometry.translation_m.rms);
}

void PrintHeader() {
  std::printf(
      "| frames | odometry noise | path (m) | odometry drift (cm) | build "
      "(s) | CPU (s) | ms/frame | frames/s | point error on planes, median (%% "
      "of "
      "depth) | plane recall / precision | max normal error (deg) | median "
      "offset error (mm) | ATE refined (cm rms) | ATE odometry (cm rms) "
      "|\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
}

int Run(const SweepOptions& o) {
  const fs::path dir = fs::temp_directory_path() /
                       ("monomap_mapping_sweep_" + std::to_string(getpid()));
  nlohmann::json j;
  j["world"] = o.world;
  j["seed"] = o.seed;
  j["width"] = o.width;
  j["height"] = o.height;
  nlohmann::json frames_json = nlohmann::json::array();
  std::printf("Frames sweep (%s, seed %llu, %dx%d, default odometry):\n\n",
              o.world.c_str(), static_cast<unsigned long long>(o.seed), o.width,
              o.height);
  PrintHeader();
  for (int f : o.frames) {
    const Point p = RunPoint(o, f, 1.0, dir);
    PrintRow(p);
    std::fflush(stdout);
    frames_json.push_back(ToJson(p));
  }
  j["frames_sweep"] = frames_json;
  nlohmann::json noise_json = nlohmann::json::array();
  std::printf(
      "\nOdometry sweep (%d frames; noise factor 1 = the simulator's "
      "default errors):\n\n",
      o.noise_frames);
  PrintHeader();
  for (double k : o.noise) {
    const Point p = RunPoint(o, o.noise_frames, k, dir);
    PrintRow(p);
    std::fflush(stdout);
    noise_json.push_back(ToJson(p));
  }
  j["odometry_sweep"] = noise_json;
  WriteFileAtomic(o.out, j.dump(2) + "\n");
  return 0;
}

}  // namespace
}  // namespace monomap

int main(int argc, char** argv) {
  monomap::ConfigureRuntime();
  monomap::SweepOptions o;
  CLI::App app{"Map building over sequence length and odometry noise"};
  app.add_option("--world", o.world, "Simulated world");
  app.add_option("--seed", o.seed, "World seed");
  app.add_option("--width", o.width, "Image width");
  app.add_option("--height", o.height, "Image height");
  app.add_option("--frames", o.frames, "Sequence lengths (comma-separated)")
      ->delimiter(',');
  app.add_option("--noise", o.noise, "Odometry error factors (comma-separated)")
      ->delimiter(',');
  app.add_option("--noise-frames", o.noise_frames,
                 "Sequence length of the odometry sweep");
  app.add_option("--out", o.out, "JSON output file");
  return monomap::ParseAndRunSweep(app, argc, argv, "mapping_sweep",
                                   [&] { return monomap::Run(o); });
}
