// One update of the localization filter on the synthetic room of
// sim/test_scene.h (kRoom: floor + 4 walls, 320x240 live camera with
// distortion): predict + render (80x60) + weigh + resample for MCL with a
// fixed count of 1000 particles, and the same plus Monte Carlo Correction
// of the 8 heaviest particles (160x120 renders, KLT, PnP) and merging for
// MCC. Also the parts: scoring 1000 renders, one MCC correction.
//
//   build-loc/bench/localization_bench --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>

#include <vector>

#include "monomap/localization/localizer.h"
#include "monomap/sim/test_scene.h"

namespace monomap {
namespace {

// The room seen from one base pose, with its live image.
testing::TestScene RoomView(const Pose2d& base) {
  testing::TestSceneOptions o;
  o.layout = testing::TestLayout::kRoom;
  o.seed = 1;
  o.room.base_poses = {base};
  o.room.render_images = true;
  o.room.gain = 0.8;
  o.room.offset = 15;
  o.room.noise_sigma = 2.0;
  return testing::MakeTestScene(o);
}

struct Scene {
  Pose2d base{0.5, 0.2, 0.4};
  testing::TestScene view = RoomView(base);
  const Map& map = view.map;
  const Camera& camera = view.camera;
  const Rigid3d& mount = view.base_from_cam;
  Renderer renderer{map};
  const Rigid3d& truth = view.world_from_cam[0];
  const cv::Mat& live = view.images[0];
};

const Scene& GetScene() {
  static const Scene scene;
  return scene;
}

void BM_Update(benchmark::State& state, LocalizationMethod method) {
  const Scene& s = GetScene();
  LocalizerOptions o;
  o.method = method;
  o.state = LocalizationState::kPlanar;
  o.mcl.num_particles = static_cast<int>(state.range(0));
  o.mcl.use_kld = false;  // a fixed count, to time what is asked
  o.init.spread_m = 0.05;
  Localizer loc(s.map, s.camera, o, s.mount);
  loc.InitializeAtPose(s.truth);
  OdometryIncrement odo;
  odo.base_prev = {0, 0, 0};
  odo.base_cur = {0.0, 0, 0};
  loc.Step(s.live, odo);  // first step: no prediction
  double weighed = 0, ess = 0, weigh_ms = 0, mcc_ms = 0;
  for (auto _ : state) {
    const LocalizerEstimate e = loc.Step(s.live, odo);
    benchmark::DoNotOptimize(e.world_from_cam.translation.x());
    weighed += e.stats.particles_weighed;
    ess += e.stats.ess;
    weigh_ms += 1e3 * e.stats.weigh_seconds;
    mcc_ms += 1e3 * e.stats.mcc_seconds;
  }
  state.counters["weigh_ms"] = weigh_ms / state.iterations();
  state.counters["mcc_ms"] = mcc_ms / state.iterations();
  state.counters["weighed"] = weighed / state.iterations();
  state.counters["ess"] = ess / state.iterations();
}

void BM_MclUpdate(benchmark::State& state) {
  BM_Update(state, LocalizationMethod::kMcl);
}
void BM_MccUpdate(benchmark::State& state) {
  BM_Update(state, LocalizationMethod::kMcc);
}
BENCHMARK(BM_MclUpdate)
    ->Arg(1000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_MccUpdate)
    ->Arg(1000)
    ->Arg(200)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Rendering + NCC of 1000 poses (parallel), without the filter around it.
void BM_ScoreBatch(benchmark::State& state) {
  const Scene& s = GetScene();
  const MeasurementModel model(&s.renderer, s.camera);
  const cv::Mat live = model.PrepareLive(s.live);
  std::vector<Rigid3d> poses;
  Rng rng(1);
  std::normal_distribution<double> n(0.0, 0.05);
  for (int i = 0; i < state.range(0); ++i) {
    poses.push_back(WorldFromCamOfBase(
        {s.base.x + n(rng), s.base.y + n(rng), s.base.yaw + n(rng)}, s.mount));
  }
  for (auto _ : state) {
    benchmark::DoNotOptimize(model.ScoreBatch(live, poses).data());
  }
}
BENCHMARK(BM_ScoreBatch)
    ->Arg(1000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// One render + NCC on the calling thread (the per-particle cost).
void BM_ScoreOne(benchmark::State& state) {
  const Scene& s = GetScene();
  const MeasurementModel model(&s.renderer, s.camera);
  const cv::Mat live = model.PrepareLive(s.live);
  for (auto _ : state) {
    benchmark::DoNotOptimize(model.Score(live, s.truth).ncc);
  }
}
BENCHMARK(BM_ScoreOne)->Unit(benchmark::kMicrosecond);

// One Monte Carlo Correction (2 render-track-solve rounds at 160x120).
void BM_MccCorrect(benchmark::State& state) {
  const Scene& s = GetScene();
  const MonteCarloCorrector mcc(&s.renderer, s.camera);
  const LiveImagePreparer prep(s.camera);
  const cv::Mat live = LiveImagePreparer::Downscale(
      prep.Undistort(s.live), mcc.options().width, mcc.options().height);
  const Rigid3d start = WorldFromCamOfBase(
      {s.base.x + 0.02, s.base.y - 0.01, s.base.yaw + 0.017}, s.mount);
  int accepted = 0;
  for (auto _ : state) {
    const MccResult r = mcc.Correct(live, start);
    accepted += r.accepted;
  }
  state.counters["accepted"] =
      static_cast<double>(accepted) / state.iterations();
}
BENCHMARK(BM_MccCorrect)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace monomap
