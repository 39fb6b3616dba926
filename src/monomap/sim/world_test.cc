#include "monomap/sim/world.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "monomap/util/error.h"

namespace monomap {
namespace {

TEST(WorldTest, EveryWorldHasValidPlanesAndTextures) {
  for (const std::string& name : WorldNames()) {
    SCOPED_TRACE(name);
    const World w = MakeWorld(name, 3, 80.0);
    EXPECT_EQ(w.name, name);
    ASSERT_GE(w.planes.size(), 5u);
    ASSERT_GE(w.floor_plane, 0);
    EXPECT_NEAR(w.planes[w.floor_plane].plane.normal.z(), 1.0, 1e-12);
    EXPECT_GE(w.path_keypoints.size(), 3u);
    for (size_t i = 0; i < w.planes.size(); ++i) {
      const TexturedPlane& p = w.planes[i];
      EXPECT_EQ(p.id, static_cast<int>(i));
      EXPECT_NEAR(p.plane.normal.norm(), 1.0, 1e-12);
      EXPECT_NEAR(p.frame.u_axis.norm(), 1.0, 1e-12);
      EXPECT_NEAR(p.frame.v_axis.norm(), 1.0, 1e-12);
      EXPECT_NEAR(p.frame.u_axis.dot(p.frame.v_axis), 0.0, 1e-12);
      EXPECT_LT((p.frame.Normal() - p.plane.normal).norm(), 1e-12);
      EXPECT_NEAR(p.plane.SignedDistance(p.frame.origin), 0.0, 1e-12);
      ASSERT_EQ(p.texture.type(), CV_8UC4);
      ASSERT_FALSE(p.texture.empty());
      Eigen::Vector2d lo, hi;
      PolygonBounds(p.polygon, &lo, &hi);
      EXPECT_GE(p.texture.cols, hi.x() * p.pixels_per_meter - 1e-6);
      EXPECT_GE(p.texture.rows, hi.y() * p.pixels_per_meter - 1e-6);
      // Not degenerate (the smallest: a door's 0.9 x 0.05 m soffit).
      EXPECT_GT(PolygonArea(p.polygon), 0.04);
      std::vector<cv::Mat> ch;
      cv::split(p.texture, ch);
      double amin = 0;
      cv::minMaxLoc(ch[3], &amin);
      EXPECT_EQ(amin, 255.0);
      cv::Scalar mean, stddev;
      cv::Mat grey;
      cv::cvtColor(p.texture, grey, cv::COLOR_BGRA2GRAY);
      cv::meanStdDev(grey, mean, stddev);
      EXPECT_GT(stddev[0], 2.0) << "plane " << i << " is uniform";
    }
  }
}

TEST(WorldTest, OfficeDoorsAreRecessedBehindTheirWallsOpenings) {
  const World w = MakeWorld("office", 2, 40.0);
  // Each door leaf is parallel to a wall, 5 cm behind it (away from the
  // corridor), and the wall's polygon leaves its opening out.
  int leaves = 0;
  for (const TexturedPlane& leaf : w.planes) {
    if (std::abs(leaf.plane.normal.z()) > 1e-9) continue;
    const double area = PolygonArea(leaf.polygon);
    if (std::abs(area - 0.9 * 2.05) > 1e-9) continue;
    const Eigen::Vector3d centre = leaf.frame.ToWorld({0.45, 1.0});
    for (const TexturedPlane& wall : w.planes) {
      if (wall.plane.normal.dot(leaf.plane.normal) < 1 - 1e-9) continue;
      const double d = wall.plane.SignedDistance(centre);
      if (std::abs(d + 0.05) > 1e-9) continue;
      ++leaves;
      // The opening in front of the leaf is not part of the wall.
      EXPECT_FALSE(PointInPolygon(
          wall.polygon, wall.frame.ToPlane(centre + 0.05 * leaf.plane.normal)));
      // Above the opening it is.
      EXPECT_TRUE(PointInPolygon(
          wall.polygon,
          wall.frame.ToPlane(centre + 0.05 * leaf.plane.normal +
                             Eigen::Vector3d(0, 0, 1.3))));
    }
  }
  EXPECT_EQ(leaves, 7);
  // One floor plane for the whole L (its polygon is the L, 32 m^2).
  EXPECT_NEAR(PolygonArea(w.planes[w.floor_plane].polygon), 2 * 10 + 2 * 6,
              1e-9);
}

TEST(WorldTest, HallwayHasHighAndLowTextureRegions) {
  const World w = MakeWorld("hallway", 5, 100.0);
  // Local contrast of 0.2 m blocks on the long walls: posters/doors are
  // busy, bare plaster is nearly flat.
  double lo = 1e9, hi = 0;
  for (int i = 0; i < 2; ++i) {
    cv::Mat grey;
    cv::cvtColor(w.planes[i].texture, grey, cv::COLOR_BGRA2GRAY);
    for (int y = 0; y + 20 <= grey.rows - 20; y += 20) {
      for (int x = 0; x + 20 <= grey.cols; x += 20) {
        cv::Scalar m, s;
        cv::meanStdDev(grey(cv::Rect(x, y, 20, 20)), m, s);
        lo = std::min(lo, s[0]);
        hi = std::max(hi, s[0]);
      }
    }
  }
  EXPECT_LT(lo, 5.0);
  EXPECT_GT(hi, 40.0);
}

TEST(WorldTest, DeterministicGivenSeed) {
  const World a = MakeWorld("room", 11, 60.0);
  const World b = MakeWorld("room", 11, 60.0);
  const World c = MakeWorld("room", 12, 60.0);
  ASSERT_EQ(a.planes.size(), b.planes.size());
  int differ = 0;
  for (size_t i = 0; i < a.planes.size(); ++i) {
    EXPECT_EQ(cv::norm(a.planes[i].texture, b.planes[i].texture,
                       cv::NORM_INF), 0.0);
    if (cv::norm(a.planes[i].texture, c.planes[i].texture, cv::NORM_INF) > 0)
      ++differ;
    else
      ADD_FAILURE() << "plane " << i << " does not depend on the seed";
  }
  EXPECT_EQ(differ, static_cast<int>(a.planes.size()));
}

TEST(WorldTest, UnknownNameListsValidNames) {
  try {
    MakeWorld("garage", 1);
    FAIL() << "no exception";
  } catch (const OptionsError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("garage"), std::string::npos);
    EXPECT_NE(what.find("hallway"), std::string::npos);
    EXPECT_NE(what.find("lab-corner"), std::string::npos);
    EXPECT_NE(what.find("room"), std::string::npos);
  }
  EXPECT_THROW(MakeWorld("room", 1, 5.0), OptionsError);
}

TEST(WorldTest, DefaultResolutionFitsMemoryBudget) {
  // Texture memory grows with ppm^2: measure at 1/5 of the default
  // resolution (building the full one takes seconds).
  for (const std::string& name : WorldNames()) {
    const double ppm = kDefaultWorldPixelsPerMeter / 5.0;
    const World w = MakeWorld(name, 1, ppm);
    const double full_mb = w.TextureBytes() * 25.0 / 1e6;
    EXPECT_LT(full_mb, 300.0) << name;
    EXPECT_GT(full_mb, 20.0) << name;
  }
}

}  // namespace
}  // namespace monomap
