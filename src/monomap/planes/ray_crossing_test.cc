#include "monomap/planes/ray_crossing.h"

#include <gtest/gtest.h>

#include <vector>

namespace monomap {
namespace {

// The plane z = 0, a landmark 1 m behind it and cameras along x at z = 2
// (in front of the plane) or z = -0.5 (behind it, on the landmark's side).
struct Scene {
  Plane plane;  // default: z = 0
  Eigen::Vector3d x{0.0, 0.0, -1.0};
  std::vector<Rigid3d> world_from_cam;
  Track track;

  void AddCamera(double cx, double cz) {
    Rigid3d pose;
    pose.translation = Eigen::Vector3d(cx, 0.0, cz);
    track.observations.push_back(
        {static_cast<int>(world_from_cam.size()), Eigen::Vector2d::Zero()});
    world_from_cam.push_back(pose);
  }
};

TEST(ForEachCrossingRayTest, HitsThePlaneWhereTheRayCrossesIt) {
  Scene s;
  s.AddCamera(3.0, 2.0);  // ray from (3, 0, 2) to (0, 0, -1) crosses at x = 1
  std::vector<Eigen::Vector3d> hits;
  ForEachCrossingRay(s.plane, s.x, s.plane.SignedDistance(s.x), s.track,
                     s.world_from_cam, 5, [&](const Eigen::Vector3d& h) {
                       hits.push_back(h);
                       return false;
                     });
  ASSERT_EQ(hits.size(), 1u);
  EXPECT_NEAR(hits[0].x(), 1.0, 1e-12);
  EXPECT_NEAR(hits[0].z(), 0.0, 1e-12);
}

TEST(ForEachCrossingRayTest, SkipsCamerasOnTheLandmarksSideAndPoseless) {
  Scene s;
  s.AddCamera(1.0, -0.5);  // behind the plane with the landmark
  s.AddCamera(0.0, 2.0);
  s.track.observations.push_back({7, Eigen::Vector2d::Zero()});  // no pose
  int calls = 0;
  ForEachCrossingRay(s.plane, s.x, s.plane.SignedDistance(s.x), s.track,
                     s.world_from_cam, 5, [&](const Eigen::Vector3d& h) {
                       EXPECT_NEAR(h.x(), 0.0, 1e-12);
                       ++calls;
                       return false;
                     });
  EXPECT_EQ(calls, 1);
}

TEST(ForEachCrossingRayTest, SpreadsRaysOverTheTrackAndStopsWhenAsked) {
  Scene s;
  for (int i = 0; i < 9; ++i) s.AddCamera(i, 2.0);
  std::vector<double> xs;
  ForEachCrossingRay(s.plane, s.x, s.plane.SignedDistance(s.x), s.track,
                     s.world_from_cam, 3, [&](const Eigen::Vector3d& h) {
                       xs.push_back(h.x());
                       return false;
                     });
  // Frames 0, 4 and 8: crossings at a third of each camera's x.
  ASSERT_EQ(xs.size(), 3u);
  EXPECT_NEAR(xs[0], 0.0, 1e-12);
  EXPECT_NEAR(xs[1], 4.0 / 3.0, 1e-12);
  EXPECT_NEAR(xs[2], 8.0 / 3.0, 1e-12);
  int calls = 0;
  ForEachCrossingRay(s.plane, s.x, s.plane.SignedDistance(s.x), s.track,
                     s.world_from_cam, 9,
                     [&](const Eigen::Vector3d&) { return ++calls == 2; });
  EXPECT_EQ(calls, 2);
}

}  // namespace
}  // namespace monomap
