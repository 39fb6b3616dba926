// Benchmarks of stage 2 (triangulation + bundle adjustment) on a synthetic
// problem of the size of a real sequence: 300 frames, 8000 tracks of mean
// length 30, 0.3 px noise, drifting odometry.
//
//   build-triangulation/bench/triangulation_bench
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "monomap/sim/test_scene.h"
#include "monomap/triangulation/bundle_adjustment.h"
#include "monomap/triangulation/triangulator.h"
#include "monomap/util/angles.h"
#include "monomap/util/stats.h"

namespace monomap {
namespace {

struct Problem {
  testing::TestScene scene;
  std::vector<Rigid3d> odometry;
  std::vector<Landmark> landmarks;  // triangulated with the odometry
};

const Problem& GetProblem() {
  static const Problem problem = [] {
    Problem p;
    testing::TestSceneOptions options;
    options.layout = testing::TestLayout::kPoints;
    options.num_frames = 300;
    options.points.num_tracks = 8000;
    options.points.min_track_length = 10;
    options.points.max_track_length = 50;
    options.points.pixel_noise_px = 0.3;
    p.scene = testing::MakeTestScene(options);
    p.odometry = testing::SimulateOdometryDrift(
        p.scene.world_from_cam, testing::OdometryDriftOptions());
    TriangulateTracks(p.scene.camera, p.odometry, p.scene.tracks,
                      TriangulationOptions(), &p.landmarks);
    return p;
  }();
  return problem;
}

void BM_TriangulateTracks(benchmark::State& state) {
  const Problem& p = GetProblem();
  TriangulationOptions options;
  options.nonlinear_refinement = state.range(0) != 0;
  TriangulationReport report;
  for (auto _ : state) {
    std::vector<Landmark> landmarks;
    report = TriangulateTracks(p.scene.camera, p.odometry, p.scene.tracks,
                               options, &landmarks);
    benchmark::DoNotOptimize(landmarks.data());
  }
  state.counters["tracks"] = report.num_tracks;
  state.counters["points"] = report.num_points;
  state.counters["mean_err_px"] = report.mean_reprojection_error_px;
}
BENCHMARK(BM_TriangulateTracks)
    ->Arg(1)
    ->Arg(0)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_BundleAdjust(benchmark::State& state) {
  const Problem& p = GetProblem();
  BundleAdjustmentOptions options;
  // 0: the direct Schur solver, 1: preconditioned CG (no automatic choice).
  options.iterative_schur = state.range(0) != 0;
  options.iterative_schur_min_covisibility = 0.0;
  options.verbose = std::getenv("MONOMAP_BA_VERBOSE") != nullptr;
  BundleAdjustmentReport report;
  for (auto _ : state) {
    state.PauseTiming();
    std::vector<Rigid3d> poses = p.odometry;
    std::vector<Landmark> landmarks = p.landmarks;
    state.ResumeTiming();
    report = BundleAdjust(p.scene.camera, p.scene.tracks, options, &poses,
                          &landmarks);
    benchmark::DoNotOptimize(landmarks.data());
  }
  // Accuracy against the truth (the first pose is shared, so no alignment).
  {
    std::vector<Rigid3d> poses = p.odometry;
    std::vector<Landmark> landmarks = p.landmarks;
    BundleAdjust(p.scene.camera, p.scene.tracks, options, &poses, &landmarks);
    auto median_point_error = [&](const std::vector<Landmark>& ls) {
      std::vector<double> e;
      for (const Landmark& l : ls) {
        e.push_back((l.x_in_world - p.scene.points[l.id]).norm());
      }
      return UpperMedian(std::move(e));
    };
    auto mean_rotation_error = [&](const std::vector<Rigid3d>& ps) {
      double sum = 0.0;
      for (size_t i = 0; i < ps.size(); ++i) {
        sum += AngleBetween(ps[i].rotation, p.scene.world_from_cam[i].rotation);
      }
      return RadToDegMulDiv(sum / ps.size());
    };
    state.counters["pt_err_mm_before"] = 1e3 * median_point_error(p.landmarks);
    state.counters["pt_err_mm_after"] = 1e3 * median_point_error(landmarks);
    state.counters["rot_err_deg_before"] = mean_rotation_error(p.odometry);
    state.counters["rot_err_deg_after"] = mean_rotation_error(poses);
  }
  state.counters["points"] = report.num_points;
  state.counters["joint"] = report.num_points_joint;
  state.counters["residuals"] = report.num_residuals;
  state.counters["iterations"] = report.iterations;
  state.counters["rms_before_px"] = report.initial_rms_error_px;
  state.counters["rms_after_px"] = report.final_rms_error_px;
  state.counters["covisibility"] = report.covisibility;
  state.SetLabel(report.linear_solver + " " + report.termination);
}
BENCHMARK(BM_BundleAdjust)
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace monomap
