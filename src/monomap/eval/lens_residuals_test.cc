#include "monomap/eval/lens_residuals.h"

#include <gtest/gtest.h>

#include <cmath>

#include "monomap/sim/test_scene.h"

namespace monomap {
namespace {

testing::TestScene Scene() {
  testing::TestSceneOptions options;
  options.layout = testing::TestLayout::kPoints;
  options.points.num_tracks = 600;
  options.num_frames = 80;
  options.points.pixel_noise_px = 0.1;
  options.seed = 5;
  return testing::MakeTestScene(options);
}

TEST(LensResiduals, RightCalibrationLeavesNoRadialOffset) {
  const testing::TestScene scene = Scene();
  const LensResidualReport report = EvaluateLensResiduals(
      scene.camera, scene.world_from_cam, scene.tracks, {});
  EXPECT_GT(report.tracks_used, 100);
  ASSERT_GE(report.rings.size(), 7u);
  for (const LensResidualRing& ring : report.rings) {
    if (ring.count < 50) continue;
    EXPECT_LT(std::abs(ring.radial_median_px), 0.05) << ring.min_radius_px;
    EXPECT_LT(std::abs(ring.tangential_median_px), 0.05) << ring.min_radius_px;
  }
}

TEST(LensResiduals, WeakerBarrelShowsAsAnInwardOffsetGrowingToTheRim) {
  const testing::TestScene scene = Scene();
  Camera wrong = scene.camera;
  wrong.distortion[0] += 0.02;  // the true lens bends more than this one
  const LensResidualReport report =
      EvaluateLensResiduals(wrong, scene.world_from_cam, scene.tracks, {});
  ASSERT_GE(report.rings.size(), 7u);
  double inner = 0.0, outer = 0.0;
  for (const LensResidualRing& ring : report.rings) {
    if (ring.count < 50) continue;
    if (ring.max_radius_px <= 200.0) {
      inner = std::max(inner, std::abs(ring.radial_median_px));
    }
    if (ring.min_radius_px >= 240.0) {
      // k1 r^3 / f^2 = 0.02 * 260^3 / 420^2 = 2 px at 260 px, less the
      // share the centre's fit absorbs (measured: -1.3 px).
      EXPECT_LT(ring.radial_median_px, -1.0) << ring.min_radius_px;
      outer = std::max(outer, -ring.radial_median_px);
    }
  }
  // The centre fixes the points: small there (a focal-length-like share of
  // the error is absorbed), large at the rim.
  EXPECT_LT(inner, 0.1);  // measured: 0.02 px
  EXPECT_GT(outer, 10 * inner);
}

}  // namespace
}  // namespace monomap
