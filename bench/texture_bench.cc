// Homographies + mosaicking on a synthetic scene of realistic size: a
// 0.6 x 0.4 m textured plane, 300 frames of 752x480 through a distorted
// camera, 40 frames blended. Images are ray-cast on demand (outside the
// timed region: they are rendered once and cached before timing).
//   build-texture/bench/texture_bench
#include <benchmark/benchmark.h>

#include <cstdio>
#include <map>
#include <memory>
#include <mutex>

#include "monomap/sim/test_scene.h"
#include "monomap/texture/image_plane_homography.h"
#include "monomap/texture/mosaic.h"

namespace monomap {
namespace {

struct BenchScene {
  Camera camera;
  std::vector<Rigid3d> poses;
  std::vector<PlaneSegment> segments;
  std::vector<Landmark> landmarks;
  std::vector<Track> tracks;
  std::vector<testing::ScenePlane> planes;
  std::unique_ptr<testing::RayCaster> caster;
  std::map<int, cv::Mat> images;  // rendered on first use
  std::mutex images_mutex;

  BenchScene() {
    camera.width = 752;
    camera.height = 480;
    camera.fx = 458.7;
    camera.fy = 457.3;
    camera.cx = 367.2;
    camera.cy = 248.4;
    camera.distortion = {-0.28, 0.074, 0.0002, 0.00002, 0.0};
    testing::TestSceneOptions o;
    o.layout = testing::TestLayout::kDesk;
    o.camera = camera;
    o.world_from_cam = DeskSweep();
    o.desk.num_features = 300;
    o.desk.feature_seed = 1;
    o.desk.texture_seed = 2;
    o.desk.texture_blobs = 60;
    testing::TestScene t = testing::MakeTestScene(o);
    poses = std::move(t.world_from_cam);
    segments = std::move(t.segments);
    landmarks = std::move(t.landmarks);
    tracks = std::move(t.tracks);
    planes = std::move(t.planes);
    caster = std::make_unique<testing::RayCaster>(camera, 1);
  }

  // A hand-held sweep over a desk: 300 frames at 0.45-0.6 m.
  static std::vector<Rigid3d> DeskSweep() {
    std::vector<Rigid3d> poses;
    for (int i = 0; i < 300; ++i) {
      const double a = 6.283185307179586 * i / 300;
      const Eigen::Vector3d eye(0.3 + 0.2 * std::cos(a),
                                0.2 + 0.12 * std::sin(a),
                                0.5 + 0.08 * std::sin(3 * a));
      const Eigen::Vector3d target(0.3 + 0.05 * std::cos(2 * a),
                                   0.2 + 0.03 * std::sin(a), 0.0);
      poses.push_back(testing::LookAt(eye, target, Eigen::Vector3d::UnitY()));
    }
    return poses;
  }

  // Rendered on first use; the mosaic calls this from several threads.
  cv::Mat Image(int f) {
    const std::lock_guard<std::mutex> lock(images_mutex);
    auto it = images.find(f);
    if (it == images.end()) {
      it = images
               .emplace(f,
                        caster->Render(poses[f], planes, f,
                                       0.85 + 0.3 * ((f * 7) % 13) / 12.0, 2.0))
               .first;
    }
    return it->second;
  }
};

BenchScene& Scene() {
  static BenchScene scene;
  return scene;
}

void BM_Homographies(benchmark::State& state) {
  BenchScene& s = Scene();
  std::vector<ImagePlaneHomography> hs;
  HomographyReport report;
  for (auto _ : state) {
    report = ComputeImagePlaneHomographies(s.camera, s.poses, s.segments,
                                           s.landmarks, s.tracks,
                                           HomographyOptions(), &hs);
  }
  state.counters["homographies"] = report.num_homographies;
  state.counters["median_residual_px"] = report.median_residual_after_px;
}
BENCHMARK(BM_Homographies)->Unit(benchmark::kMillisecond);

void BM_Mosaic(benchmark::State& state) {
  BenchScene& s = Scene();
  std::vector<ImagePlaneHomography> hs;
  ComputeImagePlaneHomographies(s.camera, s.poses, s.segments, s.landmarks,
                                s.tracks, HomographyOptions(), &hs);
  MosaicOptions options;
  options.max_frames_per_plane = 40;
  // Render the blended frames once, outside the timing.
  std::vector<TexturedPlane> planes;
  BuildTexturedPlanes(
      s.camera, s.poses, s.segments, s.landmarks, s.tracks, hs,
      [&](int f) { return s.Image(f); }, options, &planes);
  MosaicReport report;
  for (auto _ : state) {
    report = BuildTexturedPlanes(
        s.camera, s.poses, s.segments, s.landmarks, s.tracks, hs,
        [&](int f) { return s.Image(f); }, options, &planes);
  }
  const auto& p = report.planes.at(0);
  state.counters["ppm"] = p.pixels_per_meter;
  state.counters["width"] = p.width;
  state.counters["height"] = p.height;
  state.counters["frames"] = static_cast<double>(p.frames.size());
  state.counters["coverage"] = p.coverage;
  state.counters["feature_residual_max_px"] = p.feature_residual_max_px;
}
BENCHMARK(BM_Mosaic)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace
}  // namespace monomap
