#include "monomap/geometry/triangulation.h"
#include "monomap/util/random.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace monomap {
namespace {

TEST(TriangulateLinear, ExactAndNoisy) {
  const Eigen::Vector3d x(0.2, -0.1, 3.0);
  std::vector<Rigid3d> cams;
  std::vector<Eigen::Vector2d> obs;
  std::mt19937 rng(1);
  std::normal_distribution<double> noise(0.0, 0.5 / 500.0);  // 0.5 px
  for (int i = 0; i < 10; ++i) {
    // Cameras on a 0.5 m baseline looking down +z.
    const Rigid3d world_from_cam(YawRotation(0.0),
                                 Eigen::Vector3d(0.05 * i, 0.0, 0.0));
    cams.push_back(world_from_cam.Inverse());
    obs.push_back((cams.back() * x).hnormalized());
  }
  Eigen::Vector3d est;
  ASSERT_TRUE(TriangulateLinear(cams, obs, &est));
  EXPECT_LT((est - x).norm(), 1e-9);
  for (auto& o : obs) o += DrawLastFirst<Eigen::Vector2d>(noise, rng);
  ASSERT_TRUE(TriangulateLinear(cams, obs, &est));
  EXPECT_LT((est - x).norm(), 0.05);  // ~1.7% of depth at 0.5 px noise
  const double angle = MaxTriangulationAngle(cams, x);
  EXPECT_NEAR(angle, std::atan(0.2 / 3.0) + std::atan(0.25 / 3.0), 1e-3);
}

TEST(TriangulateLinear, RejectsSingleView) {
  Eigen::Vector3d est;
  EXPECT_FALSE(TriangulateLinear({Rigid3d()}, {Eigen::Vector2d(0, 0)}, &est));
}

}  // namespace
}  // namespace monomap
