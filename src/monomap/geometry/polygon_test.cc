#include "monomap/geometry/polygon.h"

#include <gtest/gtest.h>

namespace monomap {
namespace {

TEST(Polygon, HullAreaAndInside) {
  std::vector<Eigen::Vector2d> pts = {{0, 0},   {2, 0},     {2, 1}, {0, 1},
                                      {1, 0.5}, {0.5, 0.2}, {2, 0}};
  const Polygon2d hull = ConvexHull(pts);
  EXPECT_EQ(hull.size(), 4u);
  EXPECT_NEAR(PolygonArea(hull), 2.0, 1e-12);
  EXPECT_TRUE(PointInPolygon(hull, {1.0, 0.5}));
  EXPECT_FALSE(PointInPolygon(hull, {2.5, 0.5}));
  // An L shape: the notch is outside.
  const Polygon2d l = {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
  EXPECT_TRUE(PointInPolygon(l, {0.5, 1.5}));
  EXPECT_FALSE(PointInPolygon(l, {1.5, 1.5}));
  Eigen::Vector2d lo, hi;
  PolygonBounds(l, &lo, &hi);
  EXPECT_EQ(hi, Eigen::Vector2d(2, 2));
}

TEST(PolygonTest, CentroidOfAreaNotOfVertices) {
  // The L of three unit squares: centroids (0.5,0.5), (1.5,0.5), (0.5,1.5).
  const Polygon2d l = {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
  const Eigen::Vector2d c = PolygonCentroid(l);
  EXPECT_NEAR(c.x(), 2.5 / 3.0, 1e-12);
  EXPECT_NEAR(c.y(), 2.5 / 3.0, 1e-12);
  // Clockwise order and a far-off position give the same centroid.
  Polygon2d far(l.rbegin(), l.rend());
  for (auto& v : far) v += Eigen::Vector2d(1e4, -1e4);
  EXPECT_NEAR((PolygonCentroid(far) - c - Eigen::Vector2d(1e4, -1e4)).norm(),
              0.0, 1e-9);
  // No area: the mean of the vertices.
  EXPECT_EQ(PolygonCentroid({{0, 0}, {2, 2}}), Eigen::Vector2d(1, 1));
  EXPECT_EQ(PolygonCentroid({}), Eigen::Vector2d(0, 0));
}

}  // namespace
}  // namespace monomap

namespace monomap {
namespace {

TEST(Polygon, DistanceToPolygon) {
  const Polygon2d square = {{0, 0}, {2, 0}, {2, 1}, {0, 1}};
  EXPECT_DOUBLE_EQ(DistanceToPolygon(square, {1.0, 0.5}), 0.0);
  EXPECT_NEAR(DistanceToPolygon(square, {3.0, 0.5}), 1.0, 1e-12);
  EXPECT_NEAR(DistanceToPolygon(square, {1.0, -0.25}), 0.25, 1e-12);
  // Beyond a corner: the distance to the corner.
  EXPECT_NEAR(DistanceToPolygon(square, {3.0, 2.0}), std::sqrt(2.0), 1e-12);
  EXPECT_TRUE(std::isinf(DistanceToPolygon({}, {0.0, 0.0})));
}

}  // namespace
}  // namespace monomap
