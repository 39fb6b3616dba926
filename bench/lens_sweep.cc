// Lens self-calibration over seeds: issue 18's perturbed-lens bar (every
// figure within 10 % of the true lens') judged beside the filter's own
// scatter.
//
// For each world seed s and filter seed offset f: the demo pipeline (a
// simulated hallway mapped, a second traversal localized by MCC from a
// global start) once with the true lens, once with a wrong given lens (fx,
// fy x (1 + --focal-error), k1 x --k1-factor) under `build
// --refine-intrinsics`. The filter's seed is s + f, so the f runs of one s
// share their maps and differ only in the particle filter. Prints per run
// and, per world seed, the means over f: points (median over all exported
// points, % of distance) and MCC translation and rotation, absolute and
// after removing one rigid offset of the map's frame
// (LocalizationAccuracy::mean_*_rigid_*).
//
//   build/bench/lens_sweep --world-seeds 1,2,3 --filter-seeds 3
//       --out /tmp/lens_sweep.json
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "monomap/pipelines/demo.h"
#include "monomap/planes/plane_growth.h"
#include "monomap/planes/plane_hypotheses.h"
#include "monomap/sim/simulate.h"
#include "monomap/triangulation/bundle_adjustment.h"
#include "monomap/util/file.h"
#include "monomap/util/runtime.h"
#include "sweep_main.h"

namespace monomap {
namespace {

namespace fs = std::filesystem;

struct SweepOptions {
  std::vector<uint64_t> world_seeds = {1, 2, 3};
  int filter_seeds = 3;         // offsets 0 .. filter_seeds - 1
  int frames = 200;             // mapping run
  int localization_frames = 60;
  int particles = 1500;
  double focal_error = 0.01;    // given fx, fy = true x (1 + this)
  double k1_factor = 0.85;      // given k1 = true k1 x this
  // Map variants that leave the lens alone, to see how much the figures
  // move with them: plane growth, its plain cells' parallax bar, and the
  // plane hypotheses.
  bool grow_planes = PlaneGrowthOptions().enabled;
  double plain_parallax_deg = PlaneGrowthOptions().min_plain_parallax_deg;
  bool plane_hypotheses = PlaneHypothesisOptions().enabled;
  // ... and bundle adjustment's outlier solve and planar-base prior.
  double ba_outlier_threshold_px =
      BundleAdjustmentOptions().outlier_threshold_px;
  bool planar_base = PlanarBaseOptions().enabled;
  std::string out = "lens_sweep.json";
};

// Figures of one demo run: points %, MCC absolute and rigid (mm, deg).
struct Figures {
  double points_percent = 0.0;
  double mm = 0.0, deg = 0.0, rigid_mm = 0.0, rigid_deg = 0.0;
  nlohmann::json lens;  // the build report's intrinsics section
};

Figures RunOnce(const SweepOptions& o, uint64_t world_seed, uint64_t filter,
                const std::optional<Camera>& given) {
  DemoOptions d;
  d.output_dir = fs::temp_directory_path() /
                 ("monomap_lens_sweep_" + std::to_string(getpid()));
  fs::remove_all(d.output_dir);
  d.seed = world_seed;
  d.num_frames = o.frames;
  d.show_progress = false;
  d.given_camera = given;
  d.mapping.bundle_adjustment.intrinsics.enabled = given.has_value();
  d.mapping.growth.enabled = o.grow_planes;
  d.mapping.growth.min_plain_parallax_deg = o.plain_parallax_deg;
  d.mapping.hypotheses.enabled = o.plane_hypotheses;
  d.mapping.bundle_adjustment.outlier_threshold_px = o.ba_outlier_threshold_px;
  d.mapping.bundle_adjustment.planar_base.enabled = o.planar_base;
  d.localization.num_frames = o.localization_frames;
  d.localization.particles = o.particles;
  d.localization.filter_seed_offset = filter;
  const DemoReport r = RunDemo(d);
  fs::remove_all(d.output_dir);
  const LocalizationAccuracy& a = r.localization.runs.at(1).accuracy;
  Figures f;
  f.points_percent = r.structure.point_error_all.relative_percent.median;
  f.mm = 1e3 * a.mean_translation_error_m;
  f.deg = a.mean_rotation_error_deg;
  f.rigid_mm = 1e3 * a.mean_translation_error_rigid_m;
  f.rigid_deg = a.mean_rotation_error_rigid_deg;
  f.lens = r.mapping["bundle_adjustment"]["intrinsics"];
  return f;
}

nlohmann::json ToJson(const Figures& f) {
  return {{"points_percent", f.points_percent}, {"mcc_mm", f.mm},
          {"mcc_deg", f.deg},       {"mcc_rigid_mm", f.rigid_mm},
          {"mcc_rigid_deg", f.rigid_deg}};
}

void PrintRow(const std::string& label, const Figures& t, const Figures& w) {
  std::printf(
      "| %s | %.3f / %.3f | %.2f / %.2f | %.4f / %.4f | %.2f / %.2f | "
      "%.4f / %.4f (%+.0f %%) |\n",
      label.c_str(), t.points_percent, w.points_percent, t.mm, w.mm, t.deg,
      w.deg, t.rigid_mm, w.rigid_mm, t.rigid_deg, w.rigid_deg,
      100 * (w.rigid_deg / t.rigid_deg - 1));
  std::fflush(stdout);
}

// Mean of the figures of several runs.
Figures Mean(const std::vector<Figures>& runs) {
  Figures m;
  for (const Figures& f : runs) {
    m.points_percent += f.points_percent / runs.size();
    m.mm += f.mm / runs.size();
    m.deg += f.deg / runs.size();
    m.rigid_mm += f.rigid_mm / runs.size();
    m.rigid_deg += f.rigid_deg / runs.size();
  }
  return m;
}

int Run(const SweepOptions& o) {
  SimulationOptions sim;
  sim.width = DemoOptions().width;
  sim.height = DemoOptions().height;
  Camera wrong = MakeSimulationCamera(sim);
  wrong.fx *= 1 + o.focal_error;
  wrong.fy *= 1 + o.focal_error;
  wrong.distortion[0] *= o.k1_factor;
  std::printf(
      "| world seed / filter offset | points %% true / refined | MCC mm | "
      "MCC deg | rigid offset removed: mm | deg |\n|---|---|---|---|---|---|\n");
  nlohmann::json j = nlohmann::json::array();
  for (const uint64_t s : o.world_seeds) {
    std::vector<Figures> truth, refined;
    for (int f = 0; f < o.filter_seeds; ++f) {
      truth.push_back(RunOnce(o, s, f, std::nullopt));
      refined.push_back(RunOnce(o, s, f, wrong));
      PrintRow(std::to_string(s) + " / " + std::to_string(f), truth.back(),
               refined.back());
      j.push_back({{"world_seed", s},
                   {"filter_seed_offset", f},
                   {"true_lens", ToJson(truth.back())},
                   {"refined", ToJson(refined.back())},
                   {"intrinsics", refined.back().lens}});
    }
    PrintRow("**" + std::to_string(s) + ", mean**", Mean(truth),
             Mean(refined));
  }
  WriteFileAtomic(o.out, j.dump(2) + "\n");
  return 0;
}

}  // namespace
}  // namespace monomap

int main(int argc, char** argv) {
  monomap::ConfigureRuntime();
  monomap::SweepOptions o;
  CLI::App app{"Lens self-calibration against the true lens over seeds"};
  app.add_option("--world-seeds", o.world_seeds, "Hallway seeds")
      ->delimiter(',');
  app.add_option("--filter-seeds", o.filter_seeds,
                 "Filter seed offsets per world seed")
      ->check(CLI::PositiveNumber);
  app.add_option("--frames", o.frames, "Frames of the mapping run");
  app.add_option("--localization-frames", o.localization_frames,
                 "Frames of the localized traversal");
  app.add_option("--particles", o.particles, "Particle budget");
  app.add_option("--focal-error", o.focal_error,
                 "Relative error of the given focal length");
  app.add_option("--k1-factor", o.k1_factor, "Given k1 over the true k1");
  app.add_option("--out", o.out, "JSON output file");
  app.add_flag("!--no-grow-planes", o.grow_planes, "Maps without growth");
  app.add_option("--plain-parallax", o.plain_parallax_deg,
                 "Growth's parallax bar for plain cells (deg)");
  app.add_flag("--plane-hypotheses", o.plane_hypotheses,
               "Maps with plane hypotheses");
  app.add_option("--ba-outlier-threshold", o.ba_outlier_threshold_px,
                 "Bundle adjustment's outlier solve threshold (px; 0: off)");
  app.add_flag("!--no-planar-base", o.planar_base,
               "Bundle adjustment without the planar-base prior");
  return monomap::ParseAndRunSweep(app, argc, argv, "lens_sweep",
                                   [&] { return monomap::Run(o); });
}
