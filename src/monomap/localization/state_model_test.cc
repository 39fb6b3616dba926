#include "monomap/localization/state_model.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "monomap/util/error.h"

namespace monomap {
namespace {

// A camera 0.4 m above the base, looking ahead and 20 degrees up.
Rigid3d Mount() {
  Eigen::Matrix3d base_r_cam;
  base_r_cam << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  return Rigid3d(Eigen::Quaterniond(base_r_cam) *
                     QuaternionFromRotationVector({20.0 * M_PI / 180, 0, 0}),
                 {0.05, 0.0, 0.4});
}

OdometryNoise2d NoNoise2d() {
  OdometryNoise2d n;
  n.alpha1 = n.alpha2 = n.alpha3 = n.alpha4 = 0.0;
  n.floor_trans_m = n.floor_rot_rad = 0.0;
  return n;
}

TEST(PlanarStateModel, FromPoseProjectsOntoTheFloorState) {
  const PlanarStateModel state(Mount(), NoNoise2d());
  const Pose2d b{0.7, -0.2, 1.1};
  Rigid3d lifted = WorldFromCamOfBase(b, Mount());
  lifted.translation.z() += 0.1;
  const Particle p = state.FromPose(lifted);
  EXPECT_NEAR(p.base.x, b.x, 1e-12);
  EXPECT_NEAR(p.base.y, b.y, 1e-12);
  EXPECT_NEAR(p.base.yaw, b.yaw, 1e-12);
  // Back at the mount's height, and the camera pose is the base's.
  EXPECT_NEAR(p.world_from_cam.translation.z(), 0.4, 1e-12);
  EXPECT_LT((p.world_from_cam.translation -
             WorldFromCamOfBase(p.base, Mount()).translation)
                .norm(),
            1e-15);
}

TEST(PlanarStateModel, PredictMovesBaseAndCameraTogether) {
  const PlanarStateModel state(Mount(), NoNoise2d());
  Particle p =
      state.FromPose(WorldFromCamOfBase({1.0, 1.0, M_PI / 2}, Mount()));
  OdometryIncrement odometry;
  odometry.base_prev = {0.0, 0.0, 0.0};
  odometry.base_cur = {0.3, 0.0, 0.2};  // 0.3 m ahead, turned 0.2 rad
  Rng rng(1);
  state.Predict(odometry, &rng, &p);
  // Without noise: 0.3 m along the particle's heading (+y), turned.
  EXPECT_NEAR(p.base.x, 1.0, 1e-12);
  EXPECT_NEAR(p.base.y, 1.3, 1e-12);
  EXPECT_NEAR(p.base.yaw, M_PI / 2 + 0.2, 1e-12);
  EXPECT_LT((p.world_from_cam.translation -
             WorldFromCamOfBase(p.base, Mount()).translation)
                .norm(),
            1e-15);
}

TEST(PlanarStateModel, RandomAndAroundPoseCoverWhatIsAsked) {
  const PlanarStateModel state(Mount(), NoNoise2d());
  const SamplingArea area{{-1.0, 2.0}, {1.0, 3.0}};
  Rng rng(2);
  double sx = 0, sy = 0;
  const int n = 4000;
  for (int i = 0; i < n; ++i) {
    const Particle p = state.Random(area, std::nullopt, &rng);
    ASSERT_GE(p.base.x, -1.0);
    ASSERT_LE(p.base.y, 3.0);
    sx += p.base.x;
    sy += p.base.y;
  }
  EXPECT_NEAR(sx / n, 0.0, 0.03);
  EXPECT_NEAR(sy / n, 2.5, 0.015);
  const Pose2d b{0.5, 0.5, 0.3};
  const std::vector<Particle> around = state.AroundPose(
      WorldFromCamOfBase(b, Mount()), n, 0.05, 3.0 * M_PI / 180, &rng);
  ASSERT_EQ(around.size(), static_cast<size_t>(n));
  double sxx = 0, syaw = 0;
  for (const Particle& p : around) {
    sxx += (p.base.x - b.x) * (p.base.x - b.x);
    syaw += (p.base.yaw - b.yaw) * (p.base.yaw - b.yaw);
  }
  EXPECT_NEAR(std::sqrt(sxx / n), 0.05, 0.003);
  EXPECT_NEAR(std::sqrt(syaw / n), 3.0 * M_PI / 180, 0.003);
}

TEST(StateModels, KldBinsFollowTheState) {
  KldOptions o;  // 5 cm, 5 degree bins
  const PlanarStateModel planar(Mount(), NoNoise2d());
  const Particle a =
      planar.FromPose(WorldFromCamOfBase({0.01, 0.01, 0.01}, Mount()));
  const Particle b =
      planar.FromPose(WorldFromCamOfBase({0.04, 0.02, 0.02}, Mount()));
  const Particle c =
      planar.FromPose(WorldFromCamOfBase({0.07, 0.01, 0.01}, Mount()));
  EXPECT_EQ(planar.Bin(a, o), planar.Bin(b, o));
  EXPECT_NE(planar.Bin(a, o), planar.Bin(c, o));
  // Planar bins have no z, roll or pitch; 6-DoF bins tell heights apart.
  EXPECT_EQ(planar.Bin(a, o)[3], 0);
  const SixDofStateModel six(OdometryNoise6d(), {});
  Particle high = six.FromPose(a.world_from_cam);
  high.world_from_cam.translation.z() += 0.06;
  EXPECT_NE(six.Bin(six.FromPose(a.world_from_cam), o), six.Bin(high, o));
}

TEST(SixDofStateModel, RandomKeepsTheReferenceHeightAndTilt) {
  const SamplingArea area{{0.0, 0.0}, {2.0, 2.0}};
  Rng rng(3);
  const SixDofStateModel no_trajectory(OdometryNoise6d(), {});
  EXPECT_THROW(no_trajectory.Random(area, std::nullopt, &rng), StageError);
  const Rigid3d ref = WorldFromCamOfBase({0.3, 0.1, 0.7}, Mount());
  const SixDofStateModel six(OdometryNoise6d(), {ref});
  for (const std::optional<Rigid3d>& r :
       {std::optional<Rigid3d>(ref), std::optional<Rigid3d>()}) {
    const Particle p = six.Random(area, r, &rng);
    EXPECT_NEAR(p.world_from_cam.translation.z(), 0.4, 1e-12);
    const Eigen::Vector3d axis =
        p.world_from_cam.rotation * Eigen::Vector3d::UnitZ();
    EXPECT_NEAR(axis.z(), std::sin(20.0 * M_PI / 180), 1e-9);
  }
}

}  // namespace
}  // namespace monomap
