#include "monomap/geometry/pose2d.h"

#include <gtest/gtest.h>

#include <cmath>

namespace monomap {
namespace {

// A camera 0.5 m above the base, 0.1 m ahead of it, looking along the
// base's x axis (camera z = base x, camera x = -base y, camera y = -base z).
Rigid3d ForwardMount() {
  Eigen::Matrix3d base_r_cam;
  base_r_cam << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  return Rigid3d(Eigen::Quaterniond(base_r_cam), {0.1, 0.0, 0.5});
}

TEST(Pose2d, WorldFromCamOfBasePlacesTheMountedCamera) {
  // Base at (1, 2) heading +y: the camera sits 0.1 m along +y, 0.5 m up,
  // and looks along +y.
  const Rigid3d world_from_cam =
      WorldFromCamOfBase({1.0, 2.0, M_PI / 2}, ForwardMount());
  EXPECT_NEAR(world_from_cam.translation.x(), 1.0, 1e-12);
  EXPECT_NEAR(world_from_cam.translation.y(), 2.1, 1e-12);
  EXPECT_NEAR(world_from_cam.translation.z(), 0.5, 1e-12);
  const Eigen::Vector3d axis =
      world_from_cam.rotation * Eigen::Vector3d::UnitZ();
  EXPECT_NEAR(axis.y(), 1.0, 1e-12);
  EXPECT_NEAR(axis.z(), 0.0, 1e-12);
}

TEST(Pose2d, BaseRoundTrip) {
  const Rigid3d mount(QuaternionFromRotationVector({-1.9, 0.1, -0.05}),
                      {0.1, 0.02, 0.5});
  const Pose2d b{1.5, -0.7, 2.9};
  const Pose2d back = BaseOfWorldFromCam(WorldFromCamOfBase(b, mount), mount);
  EXPECT_NEAR(back.x, b.x, 1e-12);
  EXPECT_NEAR(back.y, b.y, 1e-12);
  EXPECT_NEAR(std::remainder(back.yaw - b.yaw, 2 * M_PI), 0.0, 1e-12);
}

TEST(Pose2d, BaseOfWorldFromCamDropsHeightAndTilt) {
  // A camera lifted by 0.2 m keeps the base's x, y and heading; pitched
  // (about its x axis, the base's y axis) it keeps the heading.
  const Rigid3d mount = ForwardMount();
  const Pose2d b{-0.3, 0.8, -1.2};
  Rigid3d lifted = WorldFromCamOfBase(b, mount);
  lifted.translation.z() += 0.2;
  const Pose2d back = BaseOfWorldFromCam(lifted, mount);
  EXPECT_NEAR(back.x, b.x, 1e-12);
  EXPECT_NEAR(back.y, b.y, 1e-12);
  EXPECT_NEAR(back.yaw, b.yaw, 1e-12);
  const Rigid3d pitched(
      lifted.rotation * QuaternionFromRotationVector({5.0 * M_PI / 180, 0, 0}),
      lifted.translation);
  EXPECT_NEAR(BaseOfWorldFromCam(pitched, mount).yaw, b.yaw, 1e-9);
}

}  // namespace
}  // namespace monomap
