// Frames per second of KLT tracking (tracking/klt_tracker.h) on the 300
// real 752x480 frames of desk_vamr_a:
//   TrackPreloaded/serial      KltTracker::Track on images already in memory,
//                              one thread (pyramid + LK + detection).
//   TrackPreloaded/pipelined   TrackFeatures on images in memory: pyramids
//                              built in parallel with tracking.
//   LoadAndTrack/serial        JPEG decode then Track, one after the other.
//   LoadAndTrack/pipelined     TrackFeatures with Dataset::LoadImage: decode
//                              and pyramids overlap with tracking (oneTBB).
//
//   build/bench/tracking_bench --benchmark_counters_tabular=true
#include <filesystem>
#include <functional>
#include <memory>
#include <vector>

#include <benchmark/benchmark.h>

#include "monomap/io/dataset.h"
#include "monomap/tracking/klt_tracker.h"

namespace monomap {
namespace {

const char* kDatasetDir = "/work/shared/data/desk_vamr_a";

// Loaded once for all benchmarks; nullptr if the data is missing.
const Dataset* GetDataset() {
  static const std::unique_ptr<Dataset> dataset = [] {
    if (!std::filesystem::exists(kDatasetDir)) return std::unique_ptr<Dataset>();
    return std::make_unique<Dataset>(LoadDataset(kDatasetDir));
  }();
  return dataset.get();
}

const std::vector<cv::Mat>* GetImages() {
  static const std::unique_ptr<std::vector<cv::Mat>> images = [] {
    const Dataset* dataset = GetDataset();
    if (dataset == nullptr) return std::unique_ptr<std::vector<cv::Mat>>();
    auto result = std::make_unique<std::vector<cv::Mat>>();
    for (size_t i = 0; i < dataset->frames.size(); ++i) {
      result->push_back(dataset->LoadImage(i));
    }
    return result;
  }();
  return images.get();
}

// The baseline: load and track one frame after the other on one thread.
TrackingReport SerialTrack(const std::function<cv::Mat(int)>& load, int n,
                           const KltTrackerOptions& options,
                           std::vector<Track>* tracks) {
  KltTracker tracker(options);
  for (int i = 0; i < n; ++i) tracker.Track(i, load(i));
  *tracks = tracker.FinishedTracks(2);
  TrackingReport report;
  report.mean_features_per_frame =
      static_cast<double>(tracker.TotalStats().total) / n;
  report.tracks_returned = static_cast<int64_t>(tracks->size());
  report.lost_forward_backward = tracker.TotalStats().lost_forward_backward;
  double sum = 0;
  for (const Track& t : *tracks) sum += t.observations.size();
  report.mean_track_length = tracks->empty() ? 0 : sum / tracks->size();
  return report;
}

void SetCounters(benchmark::State& state, int frames_per_iteration,
                 const TrackingReport& report) {
  state.counters["fps"] = benchmark::Counter(
      static_cast<double>(frames_per_iteration) *
          static_cast<double>(state.iterations()),
      benchmark::Counter::kIsRate);
  state.counters["features/frame"] = report.mean_features_per_frame;
  state.counters["track_len"] = report.mean_track_length;
  state.counters["tracks"] = static_cast<double>(report.tracks_returned);
  state.counters["lost_fb"] = static_cast<double>(report.lost_forward_backward);
}

void BM_TrackPreloaded(benchmark::State& state) {
  const std::vector<cv::Mat>* images = GetImages();
  if (images == nullptr) {
    state.SkipWithError("dataset desk_vamr_a missing");
    return;
  }
  const bool pipelined = state.range(0) != 0;
  const int n = static_cast<int>(images->size());
  const KltTrackerOptions options;
  TrackingReport report;
  for (auto _ : state) {
    std::vector<Track> tracks;
    if (pipelined) {
      report = TrackFeatures([&](int i) { return (*images)[i]; }, n, options,
                             &tracks);
    } else {
      report = SerialTrack([&](int i) { return (*images)[i]; }, n, options,
                           &tracks);
    }
    benchmark::DoNotOptimize(tracks.data());
  }
  SetCounters(state, n, report);
}
BENCHMARK(BM_TrackPreloaded)
    ->ArgName("pipelined")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(3);

void BM_LoadAndTrack(benchmark::State& state) {
  const Dataset* dataset = GetDataset();
  if (dataset == nullptr) {
    state.SkipWithError("dataset desk_vamr_a missing");
    return;
  }
  const bool pipelined = state.range(0) != 0;
  const int n = static_cast<int>(dataset->frames.size());
  const KltTrackerOptions options;
  TrackingReport report;
  for (auto _ : state) {
    std::vector<Track> tracks;
    if (pipelined) {
      report = TrackFeatures([&](int i) { return dataset->LoadImage(i); }, n,
                             options, &tracks);
    } else {
      report = SerialTrack([&](int i) { return dataset->LoadImage(i); }, n,
                           options, &tracks);
    }
    benchmark::DoNotOptimize(tracks.data());
  }
  SetCounters(state, n, report);
}
BENCHMARK(BM_LoadAndTrack)
    ->ArgName("pipelined")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(3);

}  // namespace
}  // namespace monomap
