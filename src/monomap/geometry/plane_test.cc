#include "monomap/geometry/plane.h"

#include <gtest/gtest.h>

#include <random>

#include "monomap/geometry/homography.h"
#include "monomap/util/angles.h"

namespace monomap {
namespace {

TEST(Plane, LeastSquaresRecoversNoisyPlane) {
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.001);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  Plane truth;
  truth.normal = Eigen::Vector3d(0.2, -0.3, 1.0).normalized();
  truth.offset = -0.7;
  const PlaneFrame f = MakePlaneFrame(truth, Eigen::Vector3d::Zero(),
                                      Eigen::Vector3d::UnitX());
  std::vector<Eigen::Vector3d> pts;
  for (int i = 0; i < 500; ++i) {
    const double n = noise(rng);
    const Eigen::Vector2d st{uni(rng), uni(rng)};
    pts.push_back(f.ToWorld(st) + n * truth.normal);
  }
  const Plane fit = FitPlaneLeastSquares(pts);
  EXPECT_LT(PlaneAngle(fit, truth), DegToRad(0.2));
  for (const auto& p : pts) EXPECT_LT(std::abs(fit.SignedDistance(p)), 0.006);
}

TEST(Plane, FrameIsOrthonormalAndOnPlane) {
  Plane p;
  p.normal = Eigen::Vector3d(1, 1, 0).normalized();
  p.offset = 2.0;
  const PlaneFrame f = MakePlaneFrame(p, Eigen::Vector3d(5, 5, 5),
                                      Eigen::Vector3d::UnitZ());
  EXPECT_NEAR(p.SignedDistance(f.origin), 0.0, 1e-12);
  EXPECT_NEAR(f.u_axis.dot(f.v_axis), 0.0, 1e-12);
  EXPECT_NEAR((f.Normal() - p.normal).norm(), 0.0, 1e-12);
  const Eigen::Vector2d st(0.3, -0.4);
  EXPECT_LT((f.ToPlane(f.ToWorld(st)) - st).norm(), 1e-12);
}

TEST(Plane, TransformedKeepsIncidence) {
  Plane p;
  p.normal = Eigen::Vector3d(0, 0, 1);
  p.offset = -1.0;
  const Rigid3d t(Eigen::Quaterniond(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitX())),
                  Eigen::Vector3d(1, 2, 3));
  const Plane q = p.Transformed(t);
  const Eigen::Vector3d x(0.3, 0.7, 1.0);
  EXPECT_NEAR(q.SignedDistance(t * x), 0.0, 1e-12);
}

TEST(Homography, MatchesDirectProjection) {
  Plane p;
  p.normal = Eigen::Vector3d(0, 0, 1);
  p.offset = 0.0;
  const PlaneFrame f = MakePlaneFrame(p, Eigen::Vector3d(0.1, 0.2, 0),
                                      Eigen::Vector3d(1, 1, 0));
  const Rigid3d cam_from_world(
      Eigen::Quaterniond(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX())),
      Eigen::Vector3d(0.0, 0.0, 1.5));
  const Eigen::Matrix3d h = NormalizedImageFromPlane(cam_from_world, f);
  const Eigen::Vector2d st(0.25, -0.1);
  const Eigen::Vector3d x_cam = cam_from_world * f.ToWorld(st);
  EXPECT_LT((ApplyHomography(h, st) - x_cam.hnormalized()).norm(), 1e-12);
}

}  // namespace
}  // namespace monomap
