// Issue 18 item 4, end to end: a simulated hallway mapped and its second
// traversal localized (demo pipeline) with the true lens, with a perturbed
// calibration (fx, fy +1 %, k1 x 0.85) as given, and with that perturbed
// calibration under lens self-calibration (build --refine-intrinsics: focal
// length and k1, k2). Seed 1, 200 frames, MCC over 60 frames from a global
// start; figures in docs/benchmarks.md ("Lens self-calibration"): with the
// focal length refined every figure is within the 10 % of the true
// lens'.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <string>

#include "monomap/io/map_format.h"
#include "monomap/pipelines/demo.h"
#include "monomap/sim/simulate.h"

namespace monomap {
namespace {

struct LensRun {
  double point_median_percent = 0.0;  // all exported points, % of distance
  int planes_matched = 0;
  double mcc_mean_translation_m = 0.0;  // once within the thresholds
  double mcc_mean_rotation_deg = 0.0;
  double mcc_fraction_within = 0.0;
  // The same after removing one rigid offset of the map's frame
  // (LocalizationAccuracy): even the true lens' map frame is turned off the
  // truth's, so the absolute rotation compares frames too.
  double mcc_rigid_translation_m = 0.0;
  double mcc_rigid_rotation_deg = 0.0;
  DemoReport report;
  Map map;  // as written to map.json
};

LensRun RunWithLens(const std::string& name, const std::optional<Camera>& given,
                    bool refine) {
  DemoOptions o;
  o.output_dir = std::filesystem::temp_directory_path() /
                 ("monomap_lens_test_" + std::to_string(::getpid()) + name);
  std::filesystem::remove_all(o.output_dir);
  o.num_frames = 200;
  o.show_progress = false;
  o.given_camera = given;
  o.mapping.bundle_adjustment.intrinsics.enabled = refine;
  o.localization.num_frames = 60;
  o.localization.particles = 1500;
  LensRun run;
  run.report = RunDemo(o);
  run.map = ReadMap(run.report.map_dir);
  const StructureAccuracy& s = run.report.structure;
  run.point_median_percent = s.point_error_all.relative_percent.median;
  for (const TruePlaneResult& t : s.true_plane_results) {
    run.planes_matched += t.matched ? 1 : 0;
  }
  const DemoLocalizationRun& mcc = run.report.localization.runs.at(1);
  EXPECT_EQ(mcc.name, "MCC");
  run.mcc_mean_translation_m = mcc.accuracy.mean_translation_error_m;
  run.mcc_mean_rotation_deg = mcc.accuracy.mean_rotation_error_deg;
  run.mcc_fraction_within = mcc.accuracy.fraction_within;
  run.mcc_rigid_translation_m = mcc.accuracy.mean_translation_error_rigid_m;
  run.mcc_rigid_rotation_deg = mcc.accuracy.mean_rotation_error_rigid_deg;
  std::printf(
      "%-10s points %.3f %% (%d planes matched); MCC %.1f mm, %.4f deg, "
      "%.0f %% of steps within; one rigid offset removed %.2f mm, %.4f deg\n",
      name.c_str(), run.point_median_percent, run.planes_matched,
      1e3 * run.mcc_mean_translation_m, run.mcc_mean_rotation_deg,
      100 * run.mcc_fraction_within, 1e3 * run.mcc_rigid_translation_m,
      run.mcc_rigid_rotation_deg);
  std::filesystem::remove_all(o.output_dir);
  return run;
}

TEST(LensSelfCalibrationTest, PerturbedLensMapsAndLocalizesAsTheTrueLens) {
  SimulationOptions sim;
  sim.width = DemoOptions().width;
  sim.height = DemoOptions().height;
  const Camera true_lens = MakeSimulationCamera(sim);
  Camera perturbed = true_lens;
  perturbed.fx *= 1.01;
  perturbed.fy *= 1.01;
  perturbed.distortion[0] *= 0.85;

  const LensRun truth = RunWithLens("true", std::nullopt, false);
  const LensRun wrong = RunWithLens("wrong", perturbed, false);
  const LensRun refined = RunWithLens("refined", perturbed, true);

  const nlohmann::json& lens =
      refined.report.mapping["bundle_adjustment"]["intrinsics"];
  std::printf("%s\n", lens.dump(1).c_str());
  EXPECT_TRUE(lens["radial_refined"].get<bool>());
  EXPECT_NEAR(lens["after"]["k1"].get<double>(), true_lens.distortion[0], 0.01);
  // The focal length comes back from 1 % off to within 0.7 %: both halves
  // of the frames constrain it and agree.
  EXPECT_TRUE(lens["focal_refined"].get<bool>());
  EXPECT_NEAR(lens["after"]["fx"].get<double>(), true_lens.fx,
              0.007 * true_lens.fx);
  EXPECT_LT(lens["halves"]["sigmas_apart"]["focal"].get<double>(), 3.0);
  // The map holds the refined lens and the calibration it was given.
  const Map& map = refined.map;
  ASSERT_TRUE(map.given_camera.has_value());
  EXPECT_EQ(map.given_camera->distortion, perturbed.distortion);
  EXPECT_NE(map.camera.distortion, perturbed.distortion);
  EXPECT_TRUE(refined.report.localization.runs.at(1).report.map_lens);

  // The perturbation matters: the given wrong lens is clearly worse ...
  EXPECT_GT(wrong.point_median_percent, 1.5 * truth.point_median_percent);
  // ... and self-calibration brings map and localization back to the true
  // lens' accuracy.
  EXPECT_EQ(refined.planes_matched, truth.planes_matched);
  EXPECT_FALSE(truth.map.given_camera.has_value());
  EXPECT_LT(refined.point_median_percent, 1.1 * truth.point_median_percent);
  EXPECT_GE(refined.mcc_fraction_within, truth.mcc_fraction_within - 0.05);
  EXPECT_LT(refined.mcc_mean_translation_m,
            1.1 * truth.mcc_mean_translation_m + 0.002);
  // Rotation: the wrong lens costs a factor ~15 absolute and ~2 with the
  // map frame's offset removed; the refined one comes back to the true
  // lens'. The bar is 25 %, not the 10 %: map changes that do not
  // touch the lens move this ratio by 12-17 points on this seed (0.89-1.11
  // with the offset removed; docs/benchmarks.md, "Lens self-calibration"),
  // so 10 % would judge noise. The 10 % is judged on bench/
  // lens_sweep's means over three worlds and filter seeds.
  EXPECT_LT(refined.mcc_mean_rotation_deg, 1.25 * truth.mcc_mean_rotation_deg);
  EXPECT_LT(refined.mcc_mean_rotation_deg, 0.25 * wrong.mcc_mean_rotation_deg);
  EXPECT_LT(refined.mcc_rigid_rotation_deg,
            1.25 * truth.mcc_rigid_rotation_deg);
  // The wrong lens' rigid rotation is 2.0x the true lens' since the tracker
  // splits failed tracks (2.4x before); the refined lens must stay well
  // clear of it.
  EXPECT_LT(refined.mcc_rigid_rotation_deg,
            0.65 * wrong.mcc_rigid_rotation_deg);
  EXPECT_LT(refined.mcc_rigid_translation_m,
            1.1 * truth.mcc_rigid_translation_m);
}

}  // namespace
}  // namespace monomap
