// Renders per second of rendering/Renderer on synthetic maps: a desk (one
// 0.8 x 0.6 m plane, 1600x1200 texture) and a hallway (7 planes, 1024x1024
// textures), at 80x60, 160x120 and 640x480, over a batch of 1000 poses,
// in three modes: one thread (tbb::global_control), the batch in parallel
// (Renderer::RenderBatch), and one by one with each render's rows in
// parallel (renders of >= 200x150 px; the latency of one large render, as
// in MCC's full-size refinement).
//
//   build/bench/rendering_bench --benchmark_counters_tabular=true
//
// Built maps too: MONOMAP_BENCH_MAPS=DIR[,DIR...] adds the same runs on
// each map directory (e.g. one built from desk_vamr_a), with the map's own
// intrinsics scaled to each size (stretched to 4:3 as the localizer's
// renders are) and 1000 poses along its trajectory, each
// moved by up to 2 cm and 2 degrees, as a particle set around the robot.
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstdlib>
#include <exception>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "monomap/io/map_format.h"
#include "monomap/rendering/renderer.h"
#include "monomap/util/angles.h"
#include "monomap/util/error.h"
#include "monomap/util/random.h"

namespace monomap {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

constexpr int kBatch = 1000;

Camera BaseCamera() {
  Camera c;
  c.width = 640;
  c.height = 480;
  c.fx = c.fy = 500;
  c.cx = 319.5;
  c.cy = 239.5;
  return c;
}

Rigid3d LookAt(const Vector3d& centre, const Vector3d& target,
               const Vector3d& up) {
  const Vector3d z = (target - centre).normalized();
  const Vector3d y = -(up - up.dot(z) * z).normalized();
  const Vector3d x = y.cross(z);
  Eigen::Matrix3d r;
  r << x, y, z;
  return Rigid3d(Eigen::Quaterniond(r), centre);
}

// Band-limited random texture with some sharp rectangles, opaque.
cv::Mat RandomTexture(int cols, int rows, uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat noise(rows / 8, cols / 8, CV_32F);
  rng.fill(noise, cv::RNG::UNIFORM, 0.0, 255.0);
  cv::Mat grey;
  cv::resize(noise, grey, cv::Size(cols, rows), 0, 0, cv::INTER_CUBIC);
  grey.convertTo(grey, CV_8U);
  for (int i = 0; i < 60; ++i) {
    const int x = rng.uniform(0, cols), y = rng.uniform(0, rows);
    // Draws in gcc's order of the arguments (util/random.h).
    const int fill = rng.uniform(0, 256), h = rng.uniform(5, rows / 8);
    cv::rectangle(grey, cv::Rect(x, y, rng.uniform(5, cols / 8), h),
                  cv::Scalar(fill), cv::FILLED);
  }
  cv::Mat bgra;
  cv::cvtColor(grey, bgra, cv::COLOR_GRAY2BGRA);
  return bgra;
}

TexturedPlane MakePlane(int id, const Vector3d& origin, const Vector3d& u,
                        const Vector3d& v, double ppm, int cols, int rows,
                        double extent_s, double extent_t) {
  TexturedPlane p;
  p.id = id;
  p.frame.origin = origin;
  p.frame.u_axis = u;
  p.frame.v_axis = v;
  p.plane.normal = u.cross(v);
  p.plane.offset = -p.plane.normal.dot(origin);
  p.pixels_per_meter = ppm;
  p.texture = RandomTexture(cols, rows, 1000 + id);
  p.polygon = {Vector2d(0, 0), Vector2d(extent_s, 0),
               Vector2d(extent_s, extent_t), Vector2d(0, extent_t)};
  return p;
}

struct Scene {
  Renderer renderer;
  std::vector<Rigid3d> poses;
};

Scene MakeDesk() {
  std::vector<TexturedPlane> planes = {
      MakePlane(0, Vector3d::Zero(), Vector3d::UnitX(), Vector3d::UnitY(),
                2000, 1600, 1200, 0.8, 0.6)};
  Scene scene{Renderer(planes), {}};
  cv::RNG rng(7);
  for (int i = 0; i < kBatch; ++i) {
    const double cz = rng.uniform(0.3, 0.6), cy = rng.uniform(-0.2, 0.4);
    const Vector3d centre(rng.uniform(0.1, 0.7), cy, cz);
    const double ty = rng.uniform(0.2, 0.4);
    const Vector3d target(rng.uniform(0.25, 0.55), ty, 0);
    const double a = rng.uniform(0.0, 2 * M_PI);
    scene.poses.push_back(
        LookAt(centre, target, Vector3d(std::cos(a), std::sin(a), 0)));
  }
  return scene;
}

// Corridor along +x, 8 m long, 2 m wide (y in [-1, 1]), 2.5 m high; normals
// face inwards.
Scene MakeHallway() {
  const double ppm = 256;  // 1024 texels = 4 m
  std::vector<TexturedPlane> planes;
  int id = 0;
  for (double x0 : {0.0, 4.0}) {
    // Floor (+z), left wall y = 1 (x cross z = -y), right wall y = -1
    // (x cross -z = +y).
    planes.push_back(MakePlane(id++, Vector3d(x0, -1, 0), Vector3d::UnitX(),
                               Vector3d::UnitY(), ppm, 1024, 1024, 4, 2));
    planes.push_back(MakePlane(id++, Vector3d(x0, 1, 0), Vector3d::UnitX(),
                               Vector3d::UnitZ(), ppm, 1024, 1024, 4, 2.5));
    planes.push_back(MakePlane(id++, Vector3d(x0, -1, 2.5), Vector3d::UnitX(),
                               -Vector3d::UnitZ(), ppm, 1024, 1024, 4, 2.5));
  }
  // End wall x = 8 (y cross -z = -x).
  planes.push_back(MakePlane(id++, Vector3d(8, -1, 2.5), Vector3d::UnitY(),
                             -Vector3d::UnitZ(), ppm, 1024, 1024, 2, 2.5));
  Scene scene{Renderer(planes), {}};
  cv::RNG rng(11);
  for (int i = 0; i < kBatch; ++i) {
    const double cz = rng.uniform(1.2, 1.7), cy = rng.uniform(-0.6, 0.6);
    const Vector3d centre(rng.uniform(0.5, 6.0), cy, cz);
    const double yaw = rng.uniform(-0.5, 0.5);
    const double pitch = rng.uniform(-0.2, 0.2);
    const Vector3d dir(std::cos(yaw) * std::cos(pitch),
                       std::sin(yaw) * std::cos(pitch), std::sin(pitch));
    scene.poses.push_back(LookAt(centre, centre + dir, Vector3d::UnitZ()));
  }
  return scene;
}

const Scene& GetScene(int which) {
  static const Scene desk = MakeDesk();
  static const Scene hallway = MakeHallway();
  return which == 0 ? desk : hallway;
}

// How the poses of a batch are rendered.
enum Mode { kOneThread = 0, kPosesParallel = 1, kRowsParallel = 2 };

const char* ModeLabel(int mode) {
  return mode == kOneThread       ? " 1-thread"
         : mode == kPosesParallel ? " tbb"
                                  : " rows";
}

// The timed loop of every benchmark here: render all poses in `mode`; sets
// the renders_per_s and foreground counters.
void RenderLoop(benchmark::State& state, const Renderer& renderer,
                const Camera& camera, const std::vector<Rigid3d>& poses,
                int mode) {
  std::vector<cv::Mat> greys(poses.size());
  cv::Mat grey;
  double foreground = 0;
  std::optional<tbb::global_control> one_thread;
  if (mode == kOneThread) {
    one_thread.emplace(tbb::global_control::max_allowed_parallelism, 1);
  }
  for (auto _ : state) {
    foreground = 0;
    if (mode == kPosesParallel) {
      for (const RenderStats& s : renderer.RenderBatch(camera, poses, &greys)) {
        foreground += static_cast<double>(s.pixels_foreground) / s.pixels_total;
      }
    } else {
      for (const Rigid3d& pose : poses) {
        const RenderStats s = renderer.Render(camera, pose, &grey);
        foreground += static_cast<double>(s.pixels_foreground) / s.pixels_total;
      }
    }
    benchmark::ClobberMemory();
  }
  state.counters["renders_per_s"] =
      benchmark::Counter(static_cast<double>(poses.size()) * state.iterations(),
                         benchmark::Counter::kIsRate);
  state.counters["foreground"] = foreground / poses.size();
}

// Args: scene (0 desk, 1 hallway), render width (4:3), Mode.
void BM_Render(benchmark::State& state) {
  const Scene& scene = GetScene(static_cast<int>(state.range(0)));
  const int width = static_cast<int>(state.range(1));
  const int mode = static_cast<int>(state.range(2));
  const Camera camera = BaseCamera().Scaled(width, width * 3 / 4);
  RenderLoop(state, scene.renderer, camera, scene.poses, mode);
  state.SetLabel(std::string(state.range(0) == 0 ? "desk" : "hallway") +
                 ModeLabel(mode));
}

BENCHMARK(BM_Render)
    ->ArgNames({"scene", "width", "mode"})
    ->ArgsProduct({{0, 1}, {80, 160, 640}, {kOneThread, kPosesParallel}})
    ->Args({0, 640, kRowsParallel})
    ->Args({1, 640, kRowsParallel})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// A built map and poses around its trajectory.
struct MapScene {
  std::unique_ptr<Renderer> renderer;
  Camera camera;
  std::vector<Rigid3d> poses;
};

MapScene LoadMapScene(const std::string& dir) {
  const Map map = ReadMap(dir);
  if (map.trajectory.empty()) {
    throw InputError(dir + ": the map has no trajectory to render around");
  }
  MapScene scene;
  scene.renderer = std::make_unique<Renderer>(map);
  scene.camera = map.camera.Pinhole();
  cv::RNG rng(13);
  auto uniform_shift = [](cv::RNG& r) { return r.uniform(-0.02, 0.02); };
  auto gaussian = [](cv::RNG& r) { return r.gaussian(1); };
  for (int i = 0; i < kBatch; ++i) {
    const Rigid3d& at =
        map.trajectory[i % map.trajectory.size()].world_from_cam;
    const Vector3d shift = DrawLastFirst<Vector3d>(uniform_shift, rng);
    const Vector3d axis = DrawLastFirst<Vector3d>(gaussian, rng).normalized();
    const double angle = DegToRadMulDiv(rng.uniform(0.0, 2.0));
    scene.poses.emplace_back(
        at.rotation * Eigen::Quaterniond(Eigen::AngleAxisd(angle, axis)),
        at.translation + shift);
  }
  return scene;
}

// Args: render width (4:3), Mode.
void BM_RenderMap(benchmark::State& state, const std::string& dir) {
  static std::vector<std::pair<std::string, MapScene>> cache;
  const MapScene* scene = nullptr;
  for (const auto& [d, s] : cache) {
    if (d == dir) scene = &s;
  }
  if (scene == nullptr) {
    try {
      cache.emplace_back(dir, LoadMapScene(dir));
    } catch (const std::exception& e) {
      state.SkipWithError(e.what());
      for (auto _ : state) {
      }
      return;
    }
    scene = &cache.back().second;
  }
  const int width = static_cast<int>(state.range(0));
  const int mode = static_cast<int>(state.range(1));
  // 4:3 whatever the map camera's aspect, as the localizer's renders.
  const int height = width * 3 / 4;
  const Camera camera = scene->camera.Scaled(width, height);
  RenderLoop(state, *scene->renderer, camera, scene->poses, mode);
  state.SetLabel(dir + " " + std::to_string(width) + "x" +
                 std::to_string(height) + ModeLabel(mode));
}

// Registered before main() runs the benchmarks; the maps load on first use.
const bool kMapsRegistered = [] {
  const char* env = std::getenv("MONOMAP_BENCH_MAPS");
  if (env == nullptr) return false;
  std::stringstream list(env);
  std::string dir;
  while (std::getline(list, dir, ',')) {
    if (dir.empty()) continue;
    benchmark::RegisterBenchmark(("BM_RenderMap/" + dir).c_str(), BM_RenderMap,
                                 dir)
        ->ArgNames({"width", "mode"})
        ->ArgsProduct({{80, 160, 640}, {kOneThread, kPosesParallel}})
        ->Args({640, kRowsParallel})
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
  }
  return true;
}();

}  // namespace
}  // namespace monomap
