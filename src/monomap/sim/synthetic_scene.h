// Moved to test_scene.h (MakeTestScene with TestLayout::kPoints). These
// names forward to it for the tests under triangulation/ that still use
// them; new code includes test_scene.h.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "monomap/sim/test_scene.h"

namespace monomap {

using testing::OdometryDriftOptions;
using testing::SimulateOdometryDrift;
using testing::SyntheticCamera;

// TestSceneOptions of the kPoints layout, flat (see PointLayoutOptions).
struct SyntheticSceneOptions {
  int num_frames = 60;
  double step_m = 0.003;
  int num_tracks = 500;
  int min_track_length = 10;
  int max_track_length = 50;
  double min_depth_m = 0.3;
  double max_depth_m = 0.6;
  double pixel_noise_px = 0.0;
  uint64_t seed = 1;
  std::optional<Camera> camera;
};

struct SyntheticScene {
  Camera camera;
  std::vector<Rigid3d> world_from_cam;
  std::vector<Eigen::Vector3d> points;
  std::vector<Track> tracks;
};

inline SyntheticScene MakeSyntheticScene(const SyntheticSceneOptions& o) {
  testing::TestSceneOptions t;
  t.layout = testing::TestLayout::kPoints;
  t.num_frames = o.num_frames;
  t.seed = o.seed;
  t.camera = o.camera;
  t.points = {o.step_m,           o.num_tracks,  o.min_track_length,
              o.max_track_length, o.min_depth_m, o.max_depth_m,
              o.pixel_noise_px};
  testing::TestScene s = testing::MakeTestScene(t);
  return {s.camera, std::move(s.world_from_cam), std::move(s.points),
          std::move(s.tracks)};
}

}  // namespace monomap
