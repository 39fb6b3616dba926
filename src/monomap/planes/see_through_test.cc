#include "monomap/planes/see_through.h"

#include <gtest/gtest.h>

#include <random>

#include "monomap/geometry/polygon.h"
#include "monomap/util/error.h"

namespace monomap {
namespace {

// A wall z = 0 seen from ten cameras 2 m in front of it (z = 2) along x,
// and a patch 6 cm in front of it over 0.5 < x < 1, 0.3 < y < 0.7.
class SeeThroughTest : public ::testing::Test {
 protected:
  void SetUp() override {
    for (int f = 0; f < 10; ++f) {
      world_from_cam_.push_back(
          Rigid3d(Eigen::Quaterniond::Identity(), {0.2 * f, 0.5, 2.0}));
    }
  }

  // Adds n landmarks uniform over [x0, x1] x [y0, y1] at height z, seen in
  // every frame; `skip_patch` leaves out those behind the patch (which a
  // real patch hides).
  std::vector<int> Add(double x0, double x1, double y0, double y1, double z,
                       int n, bool skip_patch, std::mt19937_64* rng) {
    std::uniform_real_distribution<double> uni(0.0, 1.0);
    std::vector<int> ids;
    while (static_cast<int>(ids.size()) < n) {
      const Eigen::Vector3d x(x0 + (x1 - x0) * uni(*rng),
                              y0 + (y1 - y0) * uni(*rng), z);
      if (skip_patch && x.x() > 0.5 && x.x() < 1.0 && x.y() > 0.3 &&
          x.y() < 0.7) {
        continue;
      }
      Landmark l;
      l.id = static_cast<FeatureId>(landmarks_.size());
      l.x_in_world = x;
      l.mean_depth_m = 2.0;  // inlier threshold 2 cm
      Track t;
      t.id = l.id;
      for (int f = 0; f < 10; ++f) t.observations.push_back({f, {0, 0}});
      ids.push_back(static_cast<int>(landmarks_.size()));
      landmarks_.push_back(l);
      tracks_.push_back(t);
    }
    return ids;
  }

  // A segment on plane z = height through the given landmarks.
  void AddSegment(const std::vector<int>& ids, double height) {
    PlaneSegment seg;
    seg.id = static_cast<int>(segments_.size());
    seg.plane.normal = Eigen::Vector3d::UnitZ();  // towards the cameras
    seg.plane.offset = -height;
    std::vector<Eigen::Vector3d> pts;
    for (int i : ids) {
      pts.push_back(landmarks_[i].x_in_world);
      landmarks_[i].plane_id = seg.id;
      seg.inlier_ids.push_back(landmarks_[i].id);
    }
    SetSegmentFrame(pts, &seg);
    for (const auto& x : pts) seg.inlier_st.push_back(seg.frame.ToPlane(x));
    seg.polygon = ConvexHull(seg.inlier_st);
    segments_.push_back(seg);
  }

  // The patch (segment 0, listed first so that dropping it renumbers the
  // wall) and the wall (segment 1); `hidden`: no wall point behind the
  // patch was seen. Returns the check's report.
  SeeThroughReport PatchAndWall(uint64_t seed, bool hidden,
                                const SeeThroughOptions& options) {
    std::mt19937_64 rng(seed);
    patch_ = Add(0.5, 1.0, 0.3, 0.7, 0.06, 40, false, &rng);
    wall_ = Add(0.0, 2.0, 0.0, 1.0, 0.0, 600, hidden, &rng);
    AddSegment(patch_, 0.06);
    AddSegment(wall_, 0.0);
    return DropSeeThroughSegments(options, PlaneFittingOptions(),
                                  world_from_cam_, tracks_, &landmarks_,
                                  &segments_);
  }

  std::vector<int> patch_, wall_;
  std::vector<Rigid3d> world_from_cam_;
  std::vector<Landmark> landmarks_;
  std::vector<Track> tracks_;
  std::vector<PlaneSegment> segments_;
};

TEST_F(SeeThroughTest, ALayerInFrontOfTheWallItsPointsShowIsDropped) {
  // Drifted features as a layer 6 cm in front of a wall whose own points
  // behind the layer were tracked and triangulated: the cameras saw through
  // the layer, so it is no surface.
  const SeeThroughReport r = PatchAndWall(1, false, SeeThroughOptions());
  ASSERT_EQ(r.seen_through.size(), 2u);
  // About 600 x 0.2 / 2 = 60 wall points lie behind the layer.
  EXPECT_GT(r.seen_through[0], 40);
  EXPECT_LT(r.seen_through[0], 90);
  EXPECT_EQ(r.seen_through[1], 0);  // the layer is in front of the wall
  ASSERT_EQ(r.dropped.size(), 1u);
  EXPECT_EQ(r.dropped[0].segment_id, 0);
  EXPECT_EQ(r.dropped[0].inliers, 40);
  ASSERT_EQ(segments_.size(), 1u);
  EXPECT_EQ(segments_[0].id, 0);
  EXPECT_EQ(segments_[0].inlier_ids.size(), 600u);
  for (int i : patch_) EXPECT_EQ(landmarks_[i].plane_id, -1);
  for (int i : wall_) EXPECT_EQ(landmarks_[i].plane_id, 0);
}

TEST_F(SeeThroughTest, ARealSurfaceThatHidesTheWallIsKept) {
  // The same patch as a real surface (a box face): nothing behind it was
  // seen, so both planes stay.
  const SeeThroughReport r = PatchAndWall(2, true, SeeThroughOptions());
  EXPECT_TRUE(r.dropped.empty());
  // A few wall points just past the patch's edge, which these cameras (all
  // seeing every point) see through its rim at an angle.
  EXPECT_LT(r.seen_through[0], 10);
  EXPECT_EQ(segments_.size(), 2u);
  EXPECT_EQ(landmarks_[patch_[0]].plane_id, 0);
}

TEST_F(SeeThroughTest, DisabledKeepsEverySegmentAndBadOptionsThrow) {
  SeeThroughOptions off;
  off.enabled = false;
  const SeeThroughReport r = PatchAndWall(3, false, off);
  EXPECT_TRUE(r.dropped.empty());
  EXPECT_EQ(segments_.size(), 2u);
  SeeThroughOptions bad;
  bad.max_rays = 0;
  EXPECT_THROW(bad.Check(), OptionsError);
  bad = SeeThroughOptions();
  bad.max_seen_through_ratio = 0.0;
  EXPECT_THROW(bad.Check(), OptionsError);
}

}  // namespace
}  // namespace monomap
