#include "monomap/planes/plane_directions.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace monomap {
namespace {

constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::min(1.0, std::abs(a.normalized().dot(b.normalized())))) *
         kRadToDeg;
}

// A corridor's side wall y = -1 seen as a 2 m x 0.5 m strip: the low points
// (skirting height, long tracks) are tight, the high ones (short tracks)
// loose and pulled 6 cm off the wall together, as pose errors shared by a
// few frames pull them. Their free fit tilts by degrees.
struct Strip {
  std::vector<Eigen::Vector3d> x;
  std::vector<double> sigmas;
};

Strip BiasedWallStrip(uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  std::normal_distribution<double> gauss(0.0, 1.0);
  Strip s;
  for (int i = 0; i < 40; ++i) {
    const double z = 0.05 + 0.5 * uni(rng);
    const bool high = z > 0.15;
    const double sigma = high ? 0.04 : 0.006;
    const double bias = high ? -0.06 * (z - 0.15) / 0.4 - 0.02 : 0.0;
    s.x.emplace_back(3.0 + 2.0 * uni(rng), -1.0 + bias + sigma * gauss(rng), z);
    s.sigmas.push_back(sigma);
  }
  return s;
}

TEST(SnapToDirections, BiasedWallStripSnapsUprightToTheFloorsDirection) {
  const Strip s = BiasedWallStrip(1);
  const Plane free = FitPlaneLeastSquares(s.x);
  const Eigen::Vector3d wall_normal = Eigen::Vector3d::UnitY();
  ASSERT_GT(AngleDeg(free.normal, wall_normal), 2.0);  // the free fit tilts
  const DirectionSnap snap = SnapToDirections(
      s.x, s.sigmas, {Eigen::Vector3d::UnitZ()}, DirectionSnapOptions());
  EXPECT_EQ(snap.kind, DirectionSnap::Kind::kPerpendicular);
  EXPECT_LT(std::abs(snap.plane.normal.z()), 1e-9);  // at right angles
  EXPECT_LT(AngleDeg(snap.plane.normal, wall_normal), 1.0);
  EXPECT_GE(snap.kept_fraction, 0.9);
  EXPECT_NEAR(snap.angle_deg, AngleDeg(free.normal, snap.plane.normal), 1e-9);
  // With a second wall's direction the normal is fixed exactly.
  const DirectionSnap both =
      SnapToDirections(s.x, s.sigmas,
                       {Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX()},
                       DirectionSnapOptions());
  EXPECT_EQ(both.kind, DirectionSnap::Kind::kOrthogonal);
  EXPECT_LT(AngleDeg(both.plane.normal, wall_normal), 1e-9);
  // The snapped plane keeps the free fit's orientation.
  EXPECT_GT(both.plane.normal.dot(free.normal), 0.0);
}

TEST(SnapToDirections, WellMeasuredRampKeepsItsTilt) {
  // A 4 deg ramp, 1 m x 1 m, 2 mm noise: its points rule out the floor's
  // direction and every direction at right angles to it.
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  std::normal_distribution<double> gauss(0.0, 0.002);
  const double slope = std::tan(4.0 / kRadToDeg);
  std::vector<Eigen::Vector3d> x;
  for (int i = 0; i < 200; ++i) {
    const double a = uni(rng), b = uni(rng);
    x.emplace_back(a, b, slope * a + gauss(rng));
  }
  const std::vector<double> sigmas(x.size(), 0.002);
  const DirectionSnap snap = SnapToDirections(
      x, sigmas, {Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX()},
      DirectionSnapOptions());
  EXPECT_EQ(snap.kind, DirectionSnap::Kind::kNone);
  EXPECT_NEAR(AngleDeg(snap.plane.normal, Eigen::Vector3d::UnitZ()), 4.0, 0.1);
}

TEST(SnapToDirections, NearlyLevelPatchSnapsParallel) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  std::normal_distribution<double> gauss(0.0, 0.003);
  std::vector<Eigen::Vector3d> x;
  for (int i = 0; i < 30; ++i) {
    // A book 4 cm above the floor, its few noisy points a little tilted.
    const double a = 0.2 * uni(rng), b = 0.15 * uni(rng);
    x.emplace_back(a, b, 0.04 + 0.02 * a + gauss(rng));
  }
  const std::vector<double> sigmas(x.size(), 0.003);
  const DirectionSnap snap = SnapToDirections(
      x, sigmas, {Eigen::Vector3d::UnitZ()}, DirectionSnapOptions());
  EXPECT_EQ(snap.kind, DirectionSnap::Kind::kParallel);
  EXPECT_LT(AngleDeg(snap.plane.normal, Eigen::Vector3d::UnitZ()), 1e-9);
  EXPECT_NEAR(-snap.plane.offset * snap.plane.normal.z(), 0.042, 0.003);
}

TEST(SnapToDirections, BeyondTheLargestAngleOrWithoutDirectionsNoSnap) {
  const Strip s = BiasedWallStrip(4);
  DirectionSnapOptions options;
  const DirectionSnap none = SnapToDirections(s.x, s.sigmas, {}, options);
  EXPECT_EQ(none.kind, DirectionSnap::Kind::kNone);
  const Plane free = FitPlaneLeastSquares(s.x);
  EXPECT_LT(AngleDeg(none.plane.normal, free.normal), 1e-9);
  options.max_angle_rad = 0.5 * AngleDeg(free.normal, Eigen::Vector3d::UnitY()) /
                          kRadToDeg;
  const DirectionSnap far = SnapToDirections(
      s.x, s.sigmas, {Eigen::Vector3d::UnitZ()}, options);
  EXPECT_EQ(far.kind, DirectionSnap::Kind::kNone);
}

TEST(NormalStandardError, ShrinksWithExtentAndCount) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  std::normal_distribution<double> gauss(0.0, 0.01);
  auto patch = [&](double size, int n) {
    std::vector<Eigen::Vector3d> x;
    for (int i = 0; i < n; ++i) {
      x.emplace_back(size * uni(rng), size * uni(rng), gauss(rng));
    }
    return NormalStandardErrorRad(x);
  };
  // sigma / (size / sqrt(12) * sqrt(n)): 0.01 / (0.289 * 20) = 0.1 deg.
  EXPECT_NEAR(patch(1.0, 400) * kRadToDeg, 0.099, 0.02);
  EXPECT_GT(patch(0.2, 400), 4.0 * patch(1.0, 400));
  EXPECT_TRUE(std::isinf(NormalStandardErrorRad({{0, 0, 0}, {1, 0, 0}})));
}

}  // namespace
}  // namespace monomap
