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

// TestSceneOptions of the kPoints layout, flat.
struct SyntheticSceneOptions : testing::PointLayoutOptions {
  int num_frames = 60;
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
  t.points = o;  // the PointLayoutOptions part
  testing::TestScene s = testing::MakeTestScene(t);
  return {s.camera, std::move(s.world_from_cam), std::move(s.points),
          std::move(s.tracks)};
}

}  // namespace monomap
