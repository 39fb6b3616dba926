// FitPlanes on ~10,000 synthetic landmarks: 4 planes (floor, two walls, a
// table top) plus 20% outliers, default options (2000 hypotheses per plane);
// ProposePlaneHypotheses over the points those planes leave free.
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "monomap/planes/plane_fitting.h"
#include "monomap/planes/plane_hypotheses.h"
#include "monomap/util/random.h"

namespace monomap {
namespace {

std::vector<Landmark> MakeLandmarks(int num_points) {
  struct Rect {
    Eigen::Vector3d origin, u, v;  // u, v: edge vectors
    double share;
  };
  const std::vector<Rect> rects = {
      {{0, 0, 0}, {4, 0, 0}, {0, 3, 0}, 0.35},              // floor
      {{0, 0, 0}, {0, 3, 0}, {0, 0, 2.5}, 0.25},            // wall x = 0
      {{0, 0, 0}, {4, 0, 0}, {0, 0, 2.5}, 0.25},            // wall y = 0
      {{1.5, 1.0, 0.75}, {1.2, 0, 0}, {0, 0.8, 0}, 0.15}};  // table top
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.001);
  std::vector<Landmark> lms;
  const int num_inliers = static_cast<int>(0.8 * num_points);
  auto push = [&](const Eigen::Vector3d& x) {
    Landmark lm;
    lm.id = static_cast<FeatureId>(lms.size());
    lm.x_in_world = x;
    lm.mean_depth_m = 0.5 + 1.5 * uni(rng);
    lms.push_back(lm);
  };
  for (const auto& r : rects) {
    const int count = static_cast<int>(r.share * num_inliers);
    for (int i = 0; i < count; ++i) {
      const auto n = DrawLastFirst<Eigen::Vector3d>(noise, rng);
      const double v = uni(rng);
      push(r.origin + uni(rng) * r.u + v * r.v + n);
    }
  }
  while (static_cast<int>(lms.size()) < num_points) {
    push({-0.2 + 4.4 * uni(rng), -0.2 + 3.4 * uni(rng), -0.2 + 2.9 * uni(rng)});
  }
  return lms;
}

void BM_FitPlanes(benchmark::State& state) {
  const std::vector<Landmark> input =
      MakeLandmarks(static_cast<int>(state.range(0)));
  const PlaneFittingOptions options;
  PlaneFittingReport report;
  for (auto _ : state) {
    std::vector<Landmark> lms = input;
    std::vector<PlaneSegment> segments;
    report = FitPlanes(options, &lms, &segments);
    benchmark::DoNotOptimize(segments.data());
  }
  state.counters["planes"] = report.num_planes;
  state.counters["outliers"] = report.num_outliers;
  state.counters["hypotheses"] = report.iterations;
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_FitPlanes)->Arg(10000)->Unit(benchmark::kMillisecond);

// The argument's count of rooms like MakeLandmarks(10000)'s, 5 m apart
// along x: a longer map at the same density of points.
std::vector<Landmark> MakeRooms(int num_rooms) {
  std::vector<Landmark> lms;
  for (int r = 0; r < num_rooms; ++r) {
    for (Landmark lm : MakeLandmarks(10000)) {
      lm.id = static_cast<FeatureId>(lms.size());
      lm.x_in_world.x() += 5.0 * r;
      lms.push_back(lm);
    }
  }
  return lms;
}

// The proposal's cost in the number of free points (20 % of the points)
// as the map grows at a constant density.
void BM_ProposePlaneHypotheses(benchmark::State& state) {
  std::vector<Landmark> lms = MakeRooms(static_cast<int>(state.range(0)));
  const PlaneFittingOptions fitting;
  std::vector<PlaneSegment> segments;
  const PlaneFittingReport fitted = FitPlanes(fitting, &lms, &segments);
  const std::vector<Eigen::Vector3d> centers = {{2.0, 1.5, 1.2}};
  const PlaneHypothesisOptions options;
  size_t proposed = 0;
  for (auto _ : state) {
    const std::vector<PlaneSegment> hyps =
        ProposePlaneHypotheses(options, fitting, lms, segments, centers);
    proposed = hyps.size();
    benchmark::DoNotOptimize(hyps.data());
  }
  state.counters["free_points"] = fitted.num_outliers;
  state.counters["hypotheses"] = static_cast<double>(proposed);
}
BENCHMARK(BM_ProposePlaneHypotheses)
    ->Arg(1)
    ->Arg(2)
    ->Arg(4)
    ->Arg(8)
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace monomap
