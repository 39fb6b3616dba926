// Live localization, replayed in real time: does the filter keep up with
// the camera? A feeder thread hands a dataset's frames to a threaded
// LocalizationSession at the camera's rate (the dataset's stamps, or
// --fps), as a camera driver would; the session drops what it cannot
// process. Images are decoded before the clock starts, so only the
// filter is measured.
//
// Reports, per run: frames processed and dropped; latency from a frame's
// arrival to its pose (mean, median, 95th percentile, max); the filter's
// own time per update (wall and CPU); the CPU used (process CPU time / wall
// time, in cores); the share of updates in each status (relocalizing and lost
// are false alarms on a sequence without kidnapping); and, with ground truth,
// the errors of the processed frames and, for a global start, when the
// filter converged (frame and seconds after the first frame); and the
// steady state apart from the start-up (the first update's time, the
// frames dropped during it, and drops and latency after it).
//
//   build/bench/realtime_replay MAP DATASET --state 6dof --method mcc
//       --threads 1 --first-frame 150 --out /tmp/rt.json
#include <oneapi/tbb/global_control.h>
#include <sys/resource.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <map>
#include <set>
#include <cstdio>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "monomap/eval/localization_accuracy.h"
#include "monomap/io/dataset.h"
#include "monomap/localization/session.h"
#include "monomap/pipelines/localization_pipeline.h"
#include "monomap/util/file.h"
#include "monomap/util/runtime.h"
#include "monomap/util/stats.h"
#include "sweep_main.h"

namespace monomap {
namespace {

struct ReplayArgs {
  std::string map_dir, dataset, out;
  std::string method = "mcc", state = "planar", init = "pose";
  int particles = LocalizerOptions().mcl.num_particles;
  uint64_t seed = LocalizerOptions().seed;
  int first_frame = 0, num_frames = -1;
  // 0: the dataset's stamps; else frames at this rate.
  double fps = 0.0;
  // oneTBB threads of the whole process (the session's worker included).
  int threads = 1;
  // Frames allowed to wait for the filter.
  int max_pending = SessionOptions().max_pending_frames;
  // MccOptions::converged_px of the estimate's refinement (0: off, the
  // default): the opt-in early stop, to measure its latency.
  double refine_converged_px = 0.0;
  // The estimate's refinement (SetEstimateRefinementWidth; -1: default).
  int refine_width = -1;
};

double ProcessCpuSeconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_utime.tv_sec + u.ru_stime.tv_sec +
         1e-6 * (u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

double Percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const size_t i = static_cast<size_t>(p * (v.size() - 1) + 0.5);
  return v[std::min(i, v.size() - 1)];
}

double Mean(const std::vector<double>& v) {
  double s = 0.0;
  for (const double x : v) s += x;
  return v.empty() ? 0.0 : s / v.size();
}

std::vector<SessionFrame> PreloadFrames(const Dataset& dataset) {
  std::vector<SessionFrame> frames;
  for (size_t i = 0; i < dataset.frames.size(); ++i) {
    const DatasetFrame& f = dataset.frames[i];
    SessionFrame frame;
    frame.stamp = f.timestamp;
    frame.image = dataset.LoadImage(i);
    frame.odom_from_cam = f.odometry_world_from_cam;
    frame.odom_base = f.odometry_base;
    frames.push_back(std::move(frame));
  }
  return frames;
}

SessionOptions MakeOptions(const ReplayArgs& a) {
  SessionOptions o;
  o.localizer.method = ParseLocalizationMethod(a.method);
  o.localizer.state = ParseLocalizationState(a.state);
  o.localizer.init.kind = ParseLocalizationInit(a.init);
  o.localizer.mcl.SetParticleBudget(a.particles);
  o.localizer.seed = a.seed;
  o.max_pending_frames = a.max_pending;
  o.output_particles = false;
  o.localizer.mcc.refinement.converged_px = a.refine_converged_px;
  if (a.refine_width >= 0) {
    SetEstimateRefinementWidth(a.refine_width, "--refine-width",
                               &o.localizer.mcc);
  }
  return o;
}

// Pushes every frame at its arrival time; returns the wall time used.
double Feed(const std::vector<SessionFrame>& frames, double fps,
            LocalizationSession* session) {
  using Clock = std::chrono::steady_clock;
  const Clock::time_point start = Clock::now();
  for (size_t i = 0; i < frames.size(); ++i) {
    const double at = fps > 0 ? i / fps : frames[i].stamp - frames[0].stamp;
    std::this_thread::sleep_until(start +
                                  std::chrono::duration_cast<Clock::duration>(
                                      std::chrono::duration<double>(at)));
    session->Push(frames[i]);
  }
  session->Flush();
  return std::chrono::duration<double>(Clock::now() - start).count();
}

nlohmann::json Summarize(const std::vector<SessionResult>& results,
                         const SessionCounters& c, double wall, double cpu) {
  std::vector<double> latency, step, step_cpu;
  int relocalizing = 0, lost = 0;
  for (const SessionResult& r : results) {
    latency.push_back(r.latency_seconds);
    step.push_back(r.stats.seconds);
    step_cpu.push_back(r.stats.cpu_seconds);
    relocalizing += r.status == SessionStatus::kRelocalizing ? 1 : 0;
    lost += r.status == SessionStatus::kLost ? 1 : 0;
  }
  const double n = std::max<size_t>(1, results.size());
  return {{"frames", c.received},
          {"processed", c.processed},
          {"dropped", c.dropped},
          {"rejected", c.rejected},
          {"wall_seconds", wall},
          {"cpu_cores", cpu / wall},
          {"latency_mean_ms", 1e3 * Mean(latency)},
          {"latency_median_ms", 1e3 * UpperMedian(latency)},
          {"latency_p95_ms", 1e3 * Percentile(latency, 0.95)},
          {"latency_max_ms", 1e3 * Percentile(latency, 1.0)},
          {"update_mean_ms", 1e3 * Mean(step)},
          {"update_p95_ms", 1e3 * Percentile(step, 0.95)},
          // CPU time of the updates: what they cost whatever else runs.
          {"update_cpu_mean_ms", 1e3 * Mean(step_cpu)},
          {"update_cpu_p95_ms", 1e3 * Percentile(step_cpu, 0.95)},
          {"relocalizing_fraction", relocalizing / n},
          {"lost_fraction", lost / n}};
}

// The first update weighs and corrects the whole initial particle set and
// takes many frame periods; the frames that arrive meanwhile are dropped
// once. The steady state (frames arriving after the first pose) is reported
// apart from that start-up: drops and latency; and when the last drop was
// (the next updates still carry the initial set's many particles).
void AddSteadyState(const std::vector<SessionFrame>& frames, double fps,
                    const std::vector<SessionResult>& results,
                    const SessionCounters& c, nlohmann::json* j) {
  if (results.empty() || frames.empty()) return;
  std::map<double, double> arrival;  // stamp -> seconds after the first
  for (size_t i = 0; i < frames.size(); ++i) {
    arrival[frames[i].stamp] =
        fps > 0 ? i / fps : frames[i].stamp - frames[0].stamp;
  }
  const double first_done =
      arrival[results[0].stamp] + results[0].latency_seconds;
  std::set<double> processed;
  std::vector<double> latency;
  for (const SessionResult& r : results) {
    processed.insert(r.stamp);
    if (arrival[r.stamp] > first_done) latency.push_back(r.latency_seconds);
  }
  int steady = 0, steady_dropped = 0;
  double last_drop = 0.0;  // when the drops ended (s after the first frame)
  for (const auto& [stamp, at] : arrival) {
    if (!processed.count(stamp)) last_drop = at;
    if (at <= first_done) continue;
    ++steady;
    steady_dropped += processed.count(stamp) ? 0 : 1;
  }
  (*j)["last_drop_s"] = last_drop;
  (*j)["first_update_ms"] = 1e3 * results[0].stats.seconds;
  (*j)["startup_dropped"] = c.dropped - steady_dropped;
  (*j)["steady_frames"] = steady;
  (*j)["steady_dropped"] = steady_dropped;
  (*j)["steady_latency_mean_ms"] = 1e3 * Mean(latency);
  (*j)["steady_latency_p95_ms"] = 1e3 * Percentile(latency, 0.95);
}

void AddAccuracy(const Dataset& dataset,
                 const std::vector<SessionResult>& results, nlohmann::json* j) {
  std::vector<TimedPose> estimate, truth;
  for (const SessionResult& r : results) {
    estimate.push_back({r.stamp, r.world_from_cam});
  }
  for (const DatasetFrame& f : dataset.frames) {
    if (f.groundtruth_world_from_cam) {
      truth.push_back({f.timestamp, *f.groundtruth_world_from_cam});
    }
  }
  if (truth.empty() || estimate.empty()) return;
  const LocalizationAccuracy a = EvaluateLocalization(estimate, truth);
  (*j)["median_translation_error_m"] = Median(a.translation_error_m);
  (*j)["median_rotation_error_deg"] = Median(a.rotation_error_deg);
  (*j)["converged_step"] = a.converged_step;
  if (a.converged_step >= 0) {
    (*j)["converged_after_s"] =
        results[a.converged_step].stamp - dataset.frames.front().timestamp;
  }
}

int Run(const ReplayArgs& a) {
  const tbb::global_control threads(
      tbb::global_control::max_allowed_parallelism, a.threads);
  DatasetOptions dataset_options;
  dataset_options.first_frame = a.first_frame;
  dataset_options.num_frames = a.num_frames;
  const Dataset dataset = LoadDataset(a.dataset, dataset_options);
  const std::vector<SessionFrame> frames = PreloadFrames(dataset);
  const std::unique_ptr<LocalizationSession> session = OpenLocalizationSession(
      a.map_dir, MakeOptions(a), dataset.camera, dataset.base_from_cam);
  std::mutex mutex;
  std::vector<SessionResult> results;
  session->Start([&](const SessionResult& r) {
    std::lock_guard<std::mutex> lock(mutex);
    results.push_back(r);
  });
  const double cpu0 = ProcessCpuSeconds();
  const double wall = Feed(frames, a.fps, session.get());
  const double cpu = ProcessCpuSeconds() - cpu0;
  session->Stop();
  nlohmann::json j = Summarize(results, session->counters(), wall, cpu);
  AddSteadyState(frames, a.fps, results, session->counters(), &j);
  AddAccuracy(dataset, results, &j);
  j["map"] = a.map_dir;
  j["dataset"] = a.dataset;
  j["method"] = a.method;
  j["state"] = a.state;
  j["init"] = a.init;
  j["threads"] = a.threads;
  j["refine_converged_px"] = a.refine_converged_px;
  j["refine_width"] = a.refine_width;
  std::printf("%s\n", j.dump(2).c_str());
  if (!a.out.empty()) WriteFileAtomic(a.out, j.dump(2) + "\n");
  return 0;
}

}  // namespace
}  // namespace monomap

int main(int argc, char** argv) {
  monomap::ConfigureRuntime();
  monomap::ReplayArgs a;
  CLI::App app(
      "Replays a dataset into a live localization session at the "
      "camera's rate and reports latency, drops and CPU");
  app.add_option("map", a.map_dir, "Map directory")->required();
  app.add_option("dataset", a.dataset, "Dataset directory")->required();
  app.add_option("--out", a.out, "Write the figures as JSON");
  app.add_option("--method", a.method, "mcl | mcc")->capture_default_str();
  app.add_option("--state", a.state, "planar | 6dof")->capture_default_str();
  app.add_option("--init", a.init, "pose | global")->capture_default_str();
  app.add_option("--particles", a.particles)->capture_default_str();
  app.add_option("--seed", a.seed)->capture_default_str();
  app.add_option("--first-frame", a.first_frame)->capture_default_str();
  app.add_option("--frames", a.num_frames, "-1: all")->capture_default_str();
  app.add_option("--fps", a.fps, "0: the dataset's stamps")
      ->capture_default_str();
  app.add_option("--threads", a.threads)->capture_default_str();
  app.add_option("--max-pending", a.max_pending)->capture_default_str();
  app.add_option("--refine-converged-px", a.refine_converged_px,
                 "Stop the estimate's refinement after a round moving less "
                 "than this (px; 0: off)")
      ->capture_default_str();
  app.add_option("--refine-width", a.refine_width,
                 "The estimate's refinement width (0: off; -1: default)")
      ->capture_default_str();
  return monomap::ParseAndRunSweep(app, argc, argv, "realtime_replay",
                                   [&] { return monomap::Run(a); });
}
