#include "monomap/geometry/rigid3.h"

#include <gtest/gtest.h>

#include <cmath>

namespace monomap {
namespace {

TEST(Rigid3d, InverseAndComposition) {
  const Rigid3d a(Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized())),
                  Eigen::Vector3d(0.5, -1.0, 2.0));
  const Eigen::Vector3d x(0.1, 0.2, 0.3);
  EXPECT_LT((a.Inverse() * (a * x) - x).norm(), 1e-12);
  EXPECT_LT(((a * a.Inverse()).translation).norm(), 1e-12);
  EXPECT_LT(AngleBetween((a * a.Inverse()).rotation,
                         Eigen::Quaterniond::Identity()),
            1e-7);
  const Rigid3d b(YawRotation(1.0), Eigen::Vector3d(1, 0, 0));
  EXPECT_LT(((a * b) * x - a * (b * x)).norm(), 1e-12);
}

TEST(Rigid3d, RotationVectorRoundTrip) {
  for (const Eigen::Vector3d& w :
       {Eigen::Vector3d(0.1, -0.2, 0.3), Eigen::Vector3d(0, 0, 3.0),
        Eigen::Vector3d(1e-14, 0, 0)}) {
    const Eigen::Vector3d back =
        RotationVectorFromQuaternion(QuaternionFromRotationVector(w));
    EXPECT_LT((back - w).norm(), 1e-9) << w.transpose();
  }
}

TEST(Rigid3d, InterpolateHalfway) {
  const Rigid3d a(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, 0));
  const Rigid3d b(YawRotation(0.4), Eigen::Vector3d(2, 0, 0));
  const Rigid3d m = Interpolate(a, b, 0.5);
  EXPECT_NEAR(AngleBetween(m.rotation, YawRotation(0.2)), 0.0, 1e-7);
  EXPECT_NEAR(m.translation.x(), 1.0, 1e-12);
}

}  // namespace
}  // namespace monomap
