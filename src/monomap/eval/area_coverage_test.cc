#include "monomap/eval/area_coverage.h"

#include <gtest/gtest.h>

#include "monomap/util/angles.h"
#include "monomap/util/error.h"

namespace monomap {
namespace {

// A plane z = z0 facing the camera at the origin, polygon [s0,s1]x[t0,t1].
TexturedPlane Wall(int id, double z0, double s0, double s1, double t0,
                   double t1) {
  TexturedPlane p;
  p.id = id;
  p.plane.normal = Eigen::Vector3d(0, 0, -1);
  p.plane.offset = z0;
  p.frame.origin = Eigen::Vector3d(0, 0, z0);
  p.polygon = {{s0, t0}, {s1, t0}, {s1, t1}, {s0, t1}};
  return p;
}

// Truth: a 1x1 m panel 2 m ahead, hiding part of a 4x4 m wall 4 m ahead.
// A 640x480 camera with f = 500 at the origin sees x in +-1.28 m at 2 m
// and +-2.56 m at 4 m (y: +-0.96, +-1.92): the panel whole (1 m^2); of
// the wall 4 x 3.84 m minus the panel's 2x2 m shadow = 11.36 m^2.
Map Truth() {
  Map truth;
  truth.planes = {Wall(0, 2.0, -0.5, 0.5, -0.5, 0.5),
                  Wall(1, 4.0, -2.0, 2.0, -2.0, 2.0)};
  return truth;
}

Map CameraOnly() {
  Map map;
  map.camera.width = 640;
  map.camera.height = 480;
  map.camera.fx = map.camera.fy = 500;
  map.camera.cx = 319.5;
  map.camera.cy = 239.5;
  map.trajectory.push_back({0.0, Rigid3d()});
  return map;
}

// The map moved by `map_from_truth` (planes and trajectory).
Map Moved(const Map& map, const Rigid3d& map_from_truth) {
  Map out = map;
  for (TexturedPlane& p : out.planes) {
    p.plane = p.plane.Transformed(map_from_truth);
    p.frame.origin = map_from_truth * p.frame.origin;
    p.frame.u_axis = map_from_truth.rotation * p.frame.u_axis;
    p.frame.v_axis = map_from_truth.rotation * p.frame.v_axis;
  }
  for (TimedPose& pose : out.trajectory) {
    pose.world_from_cam = map_from_truth * pose.world_from_cam;
  }
  return out;
}

TEST(AreaCoverage, SeenAreaLeavesOutWhatIsOutOfViewOrHidden) {
  const Map truth = Truth();
  const AreaCoverage c =
      MeasureAreaCoverage(CameraOnly(), truth, Rigid3d(), AreaCoverageOptions());
  ASSERT_EQ(c.planes.size(), 2u);
  EXPECT_NEAR(c.planes[0].seen_area_m2, 1.0, 0.02);
  // Within one 5 cm row of samples along the image's edges.
  EXPECT_NEAR(c.planes[1].seen_area_m2, 11.36, 0.25);
  EXPECT_EQ(c.recovered_area_m2, 0.0);  // the map has no planes
  EXPECT_EQ(c.large_planes_seen, 2);
  EXPECT_EQ(c.large_planes_recovered, 0);
}

TEST(AreaCoverage, RecoveredAreaCountsPlanesOfTheRightOrientationAndOffset) {
  const Map truth = Truth();
  Map map = CameraOnly();
  map.planes.push_back(Wall(0, 2.0, -0.5, 0.5, -0.5, 0.5));
  // Part of the far wall (s >= 0.5), 2 cm off: within the match bounds.
  // Its seen part: 1.5 x 3.84 m minus the shadow's 0.5 x 2 m = 4.76 m^2.
  map.planes.push_back(Wall(1, 4.02, 0.5, 2.0, -2.0, 2.0));
  // The other half tilted 5 degrees: a wrong plane recovers nothing.
  TexturedPlane tilted = Wall(2, 4.0, -2.0, 0.0, -2.0, 2.0);
  tilted.plane.normal =
      Eigen::Vector3d(std::sin(DegToRad(5.0)), 0, -std::cos(DegToRad(5.0)));
  map.planes.push_back(tilted);
  // Checked in a map frame rotated and moved away from the truth's.
  const Rigid3d map_from_truth(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized())),
      Eigen::Vector3d(5, -3, 1));
  const AreaCoverage c = MeasureAreaCoverage(
      Moved(map, map_from_truth), truth, map_from_truth.Inverse(),
      AreaCoverageOptions());
  EXPECT_NEAR(c.planes[0].recovered_area_m2, 1.0, 0.02);
  EXPECT_NEAR(c.planes[1].recovered_area_m2, 4.76, 0.1);
  EXPECT_NEAR(c.area_recall, (1.0 + 4.76) / (1.0 + 11.36), 0.015);
  EXPECT_EQ(c.large_planes_recovered, 1);  // the wall has < half recovered
  // The map's own area: 1 + 6 m^2 on the truth, the tilted 8 m^2 not.
  EXPECT_NEAR(c.map_area_m2, 15.0, 0.05);
  EXPECT_NEAR(c.map_area_on_truth_m2, 7.0, 0.05);
  EXPECT_NEAR(c.area_precision, 7.0 / 15.0, 0.01);
  // 4 cm off is beyond max_distance_m: nothing of the far wall.
  map.planes[1] = Wall(1, 4.04, 0.5, 2.0, -2.0, 2.0);
  const AreaCoverage off =
      MeasureAreaCoverage(map, truth, Rigid3d(), AreaCoverageOptions());
  EXPECT_EQ(off.planes[1].recovered_area_m2, 0.0);
}

TEST(AreaCoverage, MapAreaBeyondTheTruePolygonIsNotOnTheTruth) {
  const Map truth = Truth();
  Map map = CameraOnly();
  // The panel grown 1 m to the left, where there is no panel: half of its
  // 2 m^2 is on the truth. It also recovers the panel whole.
  map.planes.push_back(Wall(0, 2.0, -1.5, 0.5, -0.5, 0.5));
  const AreaCoverage c =
      MeasureAreaCoverage(map, truth, Rigid3d(), AreaCoverageOptions());
  EXPECT_NEAR(c.planes[0].recovered_area_m2, 1.0, 0.02);
  EXPECT_NEAR(c.map_area_m2, 2.0, 0.02);
  EXPECT_NEAR(c.map_area_on_truth_m2, 1.0, 0.02);
  EXPECT_NEAR(c.area_precision, 0.5, 0.01);
  // ... and per map plane.
  ASSERT_EQ(c.map_planes.size(), 1u);
  EXPECT_EQ(c.map_planes[0].map_id, 0);
  EXPECT_NEAR(c.map_planes[0].area_m2, 2.0, 0.02);
  EXPECT_NEAR(c.map_planes[0].on_truth_m2, 1.0, 0.02);
}

TEST(AreaCoverage, ObservableAreaNeedsTwoViewsApartAndNotGrazing) {
  const Map truth = Truth();
  Map map = CameraOnly();
  const AreaCoverage one =
      MeasureAreaCoverage(map, truth, Rigid3d(), AreaCoverageOptions());
  EXPECT_EQ(one.observable_area_m2, 0.0);  // one view places nothing
  EXPECT_EQ(one.large_planes_observable, 0);
  // A second view 2 cm to the side: 0.6 deg of parallax at the panel.
  map.trajectory.push_back(
      {1.0, Rigid3d(Eigen::Quaterniond::Identity(), {0.02, 0, 0})});
  EXPECT_EQ(MeasureAreaCoverage(map, truth, Rigid3d(), AreaCoverageOptions())
                .observable_area_m2,
            0.0);
  // 30 cm to the side: 8.5 deg at the panel, >= 4.3 deg at the wall. The
  // panel is seen whole by both; of the wall, what both see.
  map.trajectory[1].world_from_cam.translation = {0.3, 0, 0};
  map.planes.push_back(Wall(0, 2.0, -0.5, 0.5, -0.5, 0.5));
  const AreaCoverage two =
      MeasureAreaCoverage(map, truth, Rigid3d(), AreaCoverageOptions());
  EXPECT_NEAR(two.planes[0].observable_area_m2, 1.0, 0.02);
  EXPECT_NEAR(two.planes[0].recovered_observable_area_m2, 1.0, 0.02);
  EXPECT_GT(two.planes[1].observable_area_m2, 9.0);
  EXPECT_LE(two.planes[1].observable_area_m2, two.planes[1].seen_area_m2);
  EXPECT_EQ(two.large_planes_observable, 2);
  EXPECT_EQ(two.large_planes_observable_recovered, 1);
  EXPECT_NEAR(two.observable_recall,
              1.0 / (two.planes[0].observable_area_m2 +
                     two.planes[1].observable_area_m2),
              1e-9);
  // Only views within 3 deg of the normal count: the panel's centre, seen
  // nearly head-on by the first camera, but at 8.5 deg by the second.
  AreaCoverageOptions head_on;
  head_on.max_incidence_deg = 3.0;
  EXPECT_EQ(MeasureAreaCoverage(map, truth, Rigid3d(), head_on)
                .planes[0]
                .observable_area_m2,
            0.0);
}

TEST(AreaCoverage, OptionsAreChecked) {
  AreaCoverageOptions o;
  o.sample_spacing_m = 0;
  EXPECT_THROW(o.Check(), OptionsError);
  o = AreaCoverageOptions();
  o.max_incidence_deg = 0;
  EXPECT_THROW(o.Check(), OptionsError);
  o = AreaCoverageOptions();
  o.min_parallax_deg = -1;
  EXPECT_THROW(o.Check(), OptionsError);
  o = AreaCoverageOptions();
  o.max_angle_deg = 95;
  EXPECT_THROW(o.Check(), OptionsError);
  o = AreaCoverageOptions();
  o.max_views = 0;
  EXPECT_THROW(o.Check(), OptionsError);
}

}  // namespace
}  // namespace monomap
