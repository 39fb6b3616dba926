#include "monomap/eval/plane_accuracy.h"

#include <gtest/gtest.h>

#include <cmath>

namespace monomap {
namespace {

// A 1 m x 0.5 m plane at z = 0, 100 texels per metre; the right half of
// the texture was never seen (alpha 0).
TexturedPlane HalfSeenPlane(int id) {
  TexturedPlane p;
  p.id = id;
  p.pixels_per_meter = 100.0;
  p.texture = cv::Mat(50, 100, CV_8UC4, cv::Scalar(128, 128, 128, 255));
  p.texture.colRange(50, 100).setTo(cv::Scalar(0, 0, 0, 0));
  return p;
}

TEST(PlaneAccuracyTest, SamplesSeenTexelsAtTheSpacing) {
  Map map;
  map.planes.push_back(HalfSeenPlane(3));
  map.planes.push_back(HalfSeenPlane(8));
  map.planes[1].frame.origin = {0.0, 0.0, 0.02};  // 2 cm off the truth
  // The distance to z = 0.
  const auto distance = [](const Eigen::Vector3d& x) {
    return std::abs(x.z());
  };
  const PlaneSurfaceAccuracy acc = EvaluatePlaneSurfaces(map, 0.1, distance);
  ASSERT_EQ(acc.planes.size(), 2u);
  EXPECT_EQ(acc.planes[0].id, 3);
  EXPECT_EQ(acc.planes[1].id, 8);
  // Every 10th texel: rows 0..40 (5), seen columns 0..40 (5).
  EXPECT_EQ(acc.planes[0].distance_m.count, 25u);
  EXPECT_NEAR(acc.planes[0].distance_m.max, 0.0, 1e-12);
  EXPECT_NEAR(acc.planes[1].distance_m.median, 0.02, 1e-12);
  EXPECT_EQ(acc.all.count, 50u);
  EXPECT_NEAR(acc.all.max, 0.02, 1e-12);
  // A spacing below one texel still samples every texel once.
  EXPECT_EQ(
      EvaluatePlaneSurfaces(map, 1e-4, distance).planes[0].distance_m.count,
      50u * 50u);
}

}  // namespace
}  // namespace monomap
