#include "monomap/planes/plane_hypotheses.h"

#include <gtest/gtest.h>

#include <cmath>

#include "monomap/geometry/polygon.h"
#include "monomap/util/error.h"

namespace monomap {
namespace {

// A segment on the plane normal . x + offset = 0, bounded by a square of
// side `size` around `centre` (projected).
PlaneSegment Segment(int id, const Eigen::Vector3d& normal, double offset,
                     const Eigen::Vector3d& centre, double size) {
  PlaneSegment seg;
  seg.id = id;
  seg.plane.normal = normal.normalized();
  seg.plane.offset = offset;
  const Eigen::Vector3d u = normal.unitOrthogonal();
  seg.frame = MakePlaneFrame(seg.plane, centre, u);
  const double h = 0.5 * size;
  seg.polygon = {{-h, -h}, {h, -h}, {h, h}, {-h, h}};
  return seg;
}

Landmark Point(FeatureId id, const Eigen::Vector3d& x, double depth) {
  Landmark l;
  l.id = id;
  l.x_in_world = x;
  l.mean_depth_m = depth;
  return l;
}

// A corridor along +y: floor z = 0 and the left wall x = -1 are fitted
// segments, seen from cameras along the corridor's axis.
struct Corridor {
  std::vector<PlaneSegment> segments = {
      Segment(0, Eigen::Vector3d::UnitZ(), 0.0, {0, 2, 0}, 3.0),
      Segment(1, Eigen::Vector3d::UnitX(), 1.0, {-1, 2, 0.6}, 3.0)};
  std::vector<Eigen::Vector3d> centers = {{0, 0, 0.4}, {0, 1, 0.4}};
};

TEST(PlaneHypotheses, DirectionsAreTheNormalsAndTheirCrossProducts) {
  const Corridor c;
  std::vector<PlaneSegment> segments = c.segments;
  // A second floor piece 2 deg off the first: the same direction.
  segments.push_back(Segment(2, Eigen::Vector3d(0, std::sin(0.035), 1), 0.0,
                             {0, 6, 0}, 1.0));
  const std::vector<Eigen::Vector3d> dirs =
      SceneDirections(PlaneHypothesisOptions(), segments);
  ASSERT_EQ(dirs.size(), 3u);
  EXPECT_NEAR(std::abs(dirs[2].y()), 1.0, 1e-9);  // floor x wall
}

TEST(PlaneHypotheses, FewPointsOnAnEndWallAndARecessedDoorMakeHypotheses) {
  const Corridor c;
  std::vector<Landmark> lms;
  FeatureId id = 0;
  // 7 points on the end wall y = 6 (a few mm of noise), 5 m away.
  for (int i = 0; i < 7; ++i) {
    lms.push_back(Point(id++, {-0.8 + 0.25 * i, 6.0 + 0.003 * ((i % 3) - 1),
                               0.2 + 0.15 * (i % 4)}, 5.0));
  }
  // 6 points on a door leaf recessed 5 cm into the left wall, 2 m away.
  for (int i = 0; i < 6; ++i) {
    lms.push_back(Point(id++, {-1.05, 2.0 + 0.15 * (i % 3), 0.3 + 0.3 * (i / 3)},
                        2.0));
  }
  // 6 points of the left wall itself beyond its polygon (y = 5): that
  // segment again, which its growth extends, not a new plane.
  for (int i = 0; i < 6; ++i) {
    lms.push_back(Point(id++, {-1.0, 5.0 + 0.1 * i, 0.3 + 0.1 * (i % 2)}, 3.0));
  }
  // Clutter: scattered points that no two directions align five of.
  for (int i = 0; i < 12; ++i) {
    lms.push_back(Point(id++, {-0.9 + 0.13 * i, 1.0 + 0.37 * i,
                               0.1 + 0.09 * ((7 * i) % 11)}, 3.0));
  }
  // A floor point within its band of the floor: the floor's.
  lms.push_back(Point(id++, {0.2, 2.0, 0.005}, 2.0));
  const std::vector<PlaneSegment> hyp = ProposePlaneHypotheses(
      PlaneHypothesisOptions(), PlaneFittingOptions(), lms, c.segments,
      c.centers);
  ASSERT_EQ(hyp.size(), 2u);
  // The end wall, facing the cameras (normal -y), ids after the segments'.
  EXPECT_EQ(hyp[0].id, 2);
  EXPECT_EQ(hyp[0].inlier_ids.size(), 7u);
  EXPECT_NEAR(hyp[0].plane.normal.y(), -1.0, 1e-9);
  EXPECT_NEAR(hyp[0].plane.SignedDistance({0, 6, 0}), 0.0, 0.004);
  EXPECT_GT(std::abs(PolygonArea(hyp[0].polygon)), 0.1);
  // The door leaf, 5 cm behind the wall, facing into the corridor.
  EXPECT_EQ(hyp[1].id, 3);
  EXPECT_EQ(hyp[1].inlier_ids.size(), 6u);
  EXPECT_NEAR(hyp[1].plane.normal.x(), 1.0, 1e-9);
  EXPECT_NEAR(hyp[1].plane.SignedDistance({-1.05, 2, 0}), 0.0, 1e-9);
  for (const PlaneSegment& h : hyp) {
    for (FeatureId f : h.inlier_ids) EXPECT_LT(f, 13u);  // no clutter
  }
}

// Hypotheses come best supported first, and taking one's points changes
// the support of every offset that counted them. On an end wall, 4 far
// points (bands of 4 cm) join 8 near ones (1 cm) at one offset, and 5 near
// points 2.5 cm off it lie on their other side: from those 5's offset the
// far points count (a group of 9), from the far points' offset the 5 do
// not. Once the 12 are taken, the 5 are a group of 5 only, and a wall of
// 7 elsewhere comes before them.
TEST(PlaneHypotheses, TakingAWallsPointsUpdatesTheSupportOfItsOffset) {
  const Corridor c;
  std::vector<Landmark> lms;
  FeatureId id = 0;
  auto row = [&](int count, double x0, double y, double depth) {
    for (int i = 0; i < count; ++i) {
      lms.push_back(Point(id, {x0 + 0.1 * i, y, 0.2 + 0.13 * id}, depth));
      ++id;
    }
  };
  row(8, -0.8, 6.0, 1.0);    // near, ids 0-7
  row(4, 0.0, 6.0, 4.0);     // far, ids 8-11
  row(5, 0.4, 6.025, 1.0);   // near, 2.5 cm off, ids 12-16
  row(7, -0.35, 8.0, 3.0);   // another wall, ids 17-23
  const std::vector<PlaneSegment> hyp = ProposePlaneHypotheses(
      PlaneHypothesisOptions(), PlaneFittingOptions(), lms, c.segments,
      c.centers);
  ASSERT_EQ(hyp.size(), 3u);
  EXPECT_EQ(hyp[0].inlier_ids.size(), 12u);
  EXPECT_EQ(hyp[1].inlier_ids.size(), 7u);
  EXPECT_NEAR(hyp[1].plane.SignedDistance({0, 8, 0}), 0.0, 1e-9);
  ASSERT_EQ(hyp[2].inlier_ids.size(), 5u);
  EXPECT_EQ(hyp[2].inlier_ids.front(), 12u);
}

TEST(PlaneHypotheses, AWallSeenAgainFurtherAlongIsNoNewPlane) {
  Corridor c;
  std::vector<Landmark> lms;
  FeatureId id = 0;
  // The left wall's 40 inliers over y in [0.5, 3.5], 5 mm of noise: its
  // normal is known to a fraction of a degree only.
  for (int i = 0; i < 40; ++i) {
    const double noise = 0.005 * (((i * 7) % 5) - 2) / 2.0;
    lms.push_back(Point(id, {-1.0 + noise, 0.5 + 0.075 * i, 0.1 + 0.1 * (i % 11)},
                        2.0));
    lms.back().plane_id = 1;
    c.segments[1].inlier_ids.push_back(id++);
  }
  // 6 points 3 m beyond its polygon, 4 cm off its plane: the fitted plane
  // may drift that far there; the wall again.
  for (int i = 0; i < 6; ++i) {
    lms.push_back(Point(id++, {-1.04, 6.5 + 0.1 * i, 0.3 + 0.2 * (i % 2)}, 3.0));
  }
  // 6 points of a door leaf 5 cm behind it within its extent: a plane.
  for (int i = 0; i < 6; ++i) {
    lms.push_back(Point(id++, {-1.05, 2.0 + 0.15 * (i % 3), 0.3 + 0.3 * (i / 3)},
                        2.0));
  }
  const std::vector<PlaneSegment> hyp = ProposePlaneHypotheses(
      PlaneHypothesisOptions(), PlaneFittingOptions(), lms, c.segments,
      c.centers);
  ASSERT_EQ(hyp.size(), 1u);
  EXPECT_NEAR(hyp[0].plane.SignedDistance({-1.05, 2, 0}), 0.0, 1e-9);
  // Without the normal's uncertainty the far points are a plane too.
  PlaneHypothesisOptions exact;
  exact.normal_error_sigmas = 0.0;
  EXPECT_EQ(ProposePlaneHypotheses(exact, PlaneFittingOptions(), lms,
                                   c.segments, c.centers)
                .size(),
            2u);
}

TEST(PlaneHypotheses, TooFewPointsOrNoDirectionsProposeNothing) {
  const Corridor c;
  std::vector<Landmark> lms;
  for (int i = 0; i < 4; ++i) {
    lms.push_back(Point(i, {-0.5 + 0.3 * i, 6.0, 0.3 + 0.1 * i}, 5.0));
  }
  EXPECT_TRUE(ProposePlaneHypotheses(PlaneHypothesisOptions(),
                                     PlaneFittingOptions(), lms, c.segments,
                                     c.centers)
                  .empty());
  lms.push_back(Point(4, {0.7, 6.0, 0.8}, 5.0));
  EXPECT_EQ(ProposePlaneHypotheses(PlaneHypothesisOptions(),
                                   PlaneFittingOptions(), lms, c.segments,
                                   c.centers)
                .size(),
            1u);
  EXPECT_TRUE(ProposePlaneHypotheses(PlaneHypothesisOptions(),
                                     PlaneFittingOptions(), lms, {}, c.centers)
                  .empty());
}

TEST(PlaneHypotheses, OptionsAreChecked) {
  PlaneHypothesisOptions o;
  o.min_points = 2;
  EXPECT_THROW(o.Check(), OptionsError);
  o = PlaneHypothesisOptions();
  o.neighbour_depth_fraction = 0;
  EXPECT_THROW(o.Check(), OptionsError);
}

}  // namespace
}  // namespace monomap
