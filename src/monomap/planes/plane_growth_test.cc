#include "monomap/planes/plane_growth.h"

#include <gtest/gtest.h>

#include "monomap/geometry/polygon.h"
#include "monomap/rendering/renderer.h"
#include "monomap/sim/test_scene.h"
#include "monomap/util/error.h"

namespace monomap {
namespace {

using testing::LiveImage;
using testing::MakeTestScene;
using testing::TestLayout;
using testing::TestScene;
using testing::TestSceneOptions;

// The localization room (floor and four blob-textured walls 1.2 m high),
// seen by a robot driving diagonally towards the front wall x = 3 (so
// points on it are seen with parallax).
TestScene Room() {
  TestSceneOptions o;
  o.layout = TestLayout::kRoom;
  o.room.render_images = true;
  o.room.noise_sigma = 2.0;
  for (int i = 0; i < 30; ++i) {
    o.room.base_poses.push_back({0.04 * i, -0.4 + 0.027 * i, 0.0});
  }
  o.num_frames = 30;
  return MakeTestScene(o);
}

// A segment on the true front wall (u = -y from y = 1.5, v = z), bounded
// by a 0.4 x 0.3 m rectangle around (u, v) = (1.5, 0.3), low in the
// middle of the wall (the camera is pitched down: the views see the wall
// up to about 0.7 m);
// `offset_m` moves the plane towards the cameras (a wrong hypothesis).
PlaneSegment FrontWallPatch(const TestScene& scene, double offset_m) {
  const TexturedPlane& wall = scene.map.planes[1];
  PlaneSegment seg;
  seg.id = 0;
  seg.plane = wall.plane;
  seg.plane.offset -= offset_m;  // n = -x: closer to the robot
  seg.frame = wall.frame;
  seg.frame.origin += offset_m * wall.plane.normal;
  seg.polygon = {{1.3, 0.15}, {1.7, 0.15}, {1.7, 0.45}, {1.3, 0.45}};
  return seg;
}

// Share of the polygon's area inside [u0, u1] x [v0, v1] (5 mm samples).
double ShareInside(const Polygon2d& poly, double u0, double u1, double v0,
                   double v1) {
  Eigen::Vector2d lo, hi;
  PolygonBounds(poly, &lo, &hi);
  int in = 0, all = 0;
  for (double s = lo.x(); s < hi.x(); s += 0.005) {
    for (double t = lo.y(); t < hi.y(); t += 0.005) {
      if (!PointInPolygon(poly, {s, t})) continue;
      ++all;
      in += (s >= u0 && s <= u1 && t >= v0 && t <= v1) ? 1 : 0;
    }
  }
  return all > 0 ? static_cast<double>(in) / all : 0.0;
}

// Growth is the default; the tests say so explicitly.
PlaneGrowthOptions GrowthOn() {
  PlaneGrowthOptions o;
  o.enabled = true;
  return o;
}

GreyImageLoader Loader(const TestScene& scene) {
  return [&scene](int frame) { return scene.images[frame]; };
}

TEST(PlaneGrowth, GrowsOverTheTexturedWallAndStopsAtItsEdges) {
  const TestScene scene = Room();
  std::vector<PlaneSegment> segments = {FrontWallPatch(scene, 0.0)};
  const PlaneGrowthReport report =
      GrowPlanePolygons(GrowthOn(), scene.camera,
                        scene.world_from_cam, {}, {}, Loader(scene), &segments);
  ASSERT_EQ(report.planes.size(), 1u);
  const PlaneGrowthStats& s = report.planes[0];
  EXPECT_NEAR(s.area_before_m2, 0.12, 1e-9);
  // The wall is 3 x 1.2 m; the views see most of its lower part (the
  // camera is pitched down). At least 1.2 m^2 of it comes back.
  EXPECT_GT(s.area_after_m2, 1.2);
  EXPECT_GT(s.cells_textured, 100);
  // ... and almost nothing beyond it: the floor below it and the side
  // walls are other planes, seen differently from each view. One cell of
  // slack around the wall's rectangle.
  const double c = s.cell_m;
  EXPECT_GT(ShareInside(segments[0].polygon, -c, 3 + c, -c, 1.2 + c), 0.97);
  // The fitted polygon stays, as what the landmarks support.
  EXPECT_NEAR(std::abs(PolygonArea(segments[0].landmark_polygon)), 0.12, 1e-9);
}

// keep_cell_maps: every cell's verdict. A grown cell shows the verdict it
// joined on (the counts match the report's); over the wall the views
// correlate through its plane, and through a plane 15 cm off they do not.
TEST(PlaneGrowth, CellMapsShowWhyEachCellJoinedOrNot) {
  const TestScene scene = Room();
  PlaneGrowthOptions o = GrowthOn();
  o.keep_cell_maps = true;
  auto grow = [&](double offset_m) {
    std::vector<PlaneSegment> segments = {FrontWallPatch(scene, offset_m)};
    return GrowPlanePolygons(o, scene.camera, scene.world_from_cam, {}, {},
                             Loader(scene), &segments)
        .planes.at(0);
  };
  // Cells of verdict v: the grown ones, or those over the wall's lower
  // 0.6 m (which the views see).
  auto count = [](const PlaneGrowthStats& s, CellVerdict v, bool grown_only) {
    const GrowthCellMap& m = s.cell_map;
    int n = 0;
    for (int r = 0; r < m.verdict.rows; ++r) {
      for (int c = 0; c < m.verdict.cols; ++c) {
        const Eigen::Vector2d st =
            m.lo + s.cell_m * Eigen::Vector2d(c + 0.5, r + 0.5);
        const bool wall =
            st.x() > 0 && st.x() < 3 && st.y() > 0 && st.y() < 0.6;
        const bool grown = m.member(r, c) && !m.fitted(r, c);
        n += m.verdict(r, c) == static_cast<uint8_t>(v) &&
             (grown_only ? grown : wall);
      }
    }
    return n;
  };
  const PlaneGrowthStats on = grow(0.0);
  const GrowthCellMap& m = on.cell_map;
  ASSERT_FALSE(m.verdict.empty());
  EXPECT_EQ(m.fitted.size(), m.verdict.size());
  EXPECT_EQ(m.member.size(), m.verdict.size());
  EXPECT_GT(on.cells_textured, 100);
  EXPECT_EQ(count(on, CellVerdict::kTextured, true), on.cells_textured);
  const PlaneGrowthStats off = grow(0.15);
  const int on_textured = count(on, CellVerdict::kTextured, false);
  const int on_inconsistent = count(on, CellVerdict::kInconsistent, false);
  const int off_textured = count(off, CellVerdict::kTextured, false);
  const int off_inconsistent = count(off, CellVerdict::kInconsistent, false);
  std::printf(
      "over the wall, textured / inconsistent cells: on it %d / %d, "
      "15 cm off %d / %d\n",
      on_textured, on_inconsistent, off_textured, off_inconsistent);
  EXPECT_GT(on_textured, 3 * on_inconsistent);
  EXPECT_GT(off_inconsistent, 2 * off_textured);
  // Off by default.
  std::vector<PlaneSegment> plain = {FrontWallPatch(scene, 0.0)};
  EXPECT_TRUE(GrowPlanePolygons(GrowthOn(), scene.camera, scene.world_from_cam,
                                {}, {}, Loader(scene), &plain)
                  .planes.at(0)
                  .cell_map.verdict.empty());
}

TEST(PlaneGrowth, AWrongPlaneDoesNotGrow) {
  const TestScene scene = Room();
  // 20 cm in front of the wall: the patches shift between views by 5-10 px.
  // (10 cm, 2-5 px of shift on this smooth blob texture, still grows: the
  // photometric test does not replace the points' accuracy, it finds where
  // the surface leaves the plane.)
  std::vector<PlaneSegment> segments = {FrontWallPatch(scene, 0.2)};
  const PlaneGrowthReport report =
      GrowPlanePolygons(GrowthOn(), scene.camera,
                        scene.world_from_cam, {}, {}, Loader(scene), &segments);
  ASSERT_EQ(report.planes.size(), 1u);
  EXPECT_LT(report.planes[0].cells_textured, 10);
  EXPECT_LT(report.planes[0].area_after_m2, 0.2);
}

// A plane hypothesis (plane_hypotheses.h) of 8 landmarks over the patch.
PlaneSegment Hypothesis(const TestScene& scene, double offset_m) {
  PlaneSegment h = FrontWallPatch(scene, offset_m);
  h.id = 1;
  for (FeatureId id = 100; id < 108; ++id) h.inlier_ids.push_back(id);
  return h;
}

// A fitted segment: the back wall, which no view sees (it does not grow).
std::vector<PlaneSegment> BackWall(const TestScene& scene) {
  const TexturedPlane& wall = scene.map.planes[2];
  PlaneSegment seg;
  seg.plane = wall.plane;
  seg.frame = wall.frame;
  seg.polygon = wall.polygon;
  return {seg};
}

TEST(PlaneGrowth, AHypothesisTheImagesConfirmJoinsAndGrows) {
  const TestScene scene = Room();
  std::vector<PlaneSegment> segments = BackWall(scene);
  const PlaneGrowthReport report =
      GrowPlanePolygons(GrowthOn(), scene.camera, scene.world_from_cam, {}, {},
                        Loader(scene), &segments, {Hypothesis(scene, 0.0)});
  ASSERT_EQ(report.hypotheses.size(), 1u);
  const HypothesisStats& h = report.hypotheses[0];
  EXPECT_TRUE(h.confirmed);
  // The images prefer its offset to 2.5 cm nearer or farther.
  EXPECT_GT(h.offset_ncc_gain, 0.0);
  EXPECT_EQ(h.inliers, 8);
  // The 0.4 x 0.3 m patch holds 12 cells of about 10 cm here (12 image
  // pixels at 2-3 m): all of them correlate.
  EXPECT_GE(h.cells_textured, 11);
  EXPECT_LE(h.cells_inconsistent, 1);
  ASSERT_EQ(segments.size(), 2u);
  EXPECT_EQ(segments[1].id, 1);
  EXPECT_EQ(h.plane_id, 1);
  EXPECT_GT(h.area_m2, 1.2);  // as a fitted patch grows
  const double c = report.planes.back().cell_m;
  EXPECT_GT(ShareInside(segments[1].polygon, -c, 3 + c, -c, 1.2 + c), 0.97);
  EXPECT_NEAR(std::abs(PolygonArea(segments[1].landmark_polygon)), 0.12, 1e-9);
}

TEST(PlaneGrowth, AHypothesisOffTheSurfaceIsNotConfirmed) {
  const TestScene scene = Room();
  std::vector<PlaneSegment> segments = BackWall(scene);
  const PlaneGrowthReport report =
      GrowPlanePolygons(GrowthOn(), scene.camera, scene.world_from_cam, {}, {},
                        Loader(scene), &segments, {Hypothesis(scene, 0.2)});
  ASSERT_EQ(report.hypotheses.size(), 1u);
  EXPECT_FALSE(report.hypotheses[0].confirmed);
  EXPECT_EQ(report.hypotheses[0].plane_id, -1);
  EXPECT_GE(report.hypotheses[0].cells_inconsistent, 11);  // of 12
  EXPECT_LE(report.hypotheses[0].cells_textured, 1);
  EXPECT_EQ(segments.size(), 1u);
}

// A hypothesis a few cm off the wall correlates across the views nearly as
// well as the wall (this smooth blob texture shifts by 1-3 px), so the
// correlation alone confirms it; moving it along its normal shows that
// the images prefer another offset.
TEST(PlaneGrowth, AHypothesisWhoseOffsetTheImagesDoNotPreferIsNotConfirmed) {
  const TestScene scene = Room();
  for (double offset_m : {0.05, -0.05}) {
    PlaneGrowthOptions options = GrowthOn();
    options.hypothesis_offset_depth_fraction = 0.0;
    std::vector<PlaneSegment> segments = BackWall(scene);
    PlaneGrowthReport report = GrowPlanePolygons(
        options, scene.camera, scene.world_from_cam, {}, {}, Loader(scene),
        &segments, {Hypothesis(scene, offset_m)});
    EXPECT_TRUE(report.hypotheses[0].confirmed) << offset_m;
    segments = BackWall(scene);
    report = GrowPlanePolygons(GrowthOn(), scene.camera, scene.world_from_cam,
                               {}, {}, Loader(scene), &segments,
                               {Hypothesis(scene, offset_m)});
    EXPECT_FALSE(report.hypotheses[0].confirmed) << offset_m;
    EXPECT_LT(report.hypotheses[0].offset_ncc_gain, 0.0) << offset_m;
    EXPECT_EQ(segments.size(), 1u);
  }
}

// The whole front wall as a fitted segment, `offset_m` towards the
// cameras.
PlaneSegment FrontWall(const TestScene& scene, double offset_m) {
  PlaneSegment seg = FrontWallPatch(scene, offset_m);
  seg.polygon = scene.map.planes[1].polygon;
  return seg;
}

TEST(PlaneGrowth, AHypothesisOverAParallelPlaneMustExplainTheImagesBetter) {
  const TestScene scene = Room();
  // The fitted wall is right: a hypothesis 20 cm in front of it, over its
  // polygon (within layer_cells), loses every cell to it.
  std::vector<PlaneSegment> segments = {FrontWall(scene, 0.0)};
  PlaneGrowthReport report =
      GrowPlanePolygons(GrowthOn(), scene.camera, scene.world_from_cam, {}, {},
                        Loader(scene), &segments, {Hypothesis(scene, 0.2)});
  ASSERT_EQ(report.hypotheses.size(), 1u);
  EXPECT_FALSE(report.hypotheses[0].confirmed);
  EXPECT_GE(report.hypotheses[0].cells_inconsistent, 11);
  EXPECT_EQ(segments.size(), 1u);
  // The fitted plane is 20 cm off (behind the wall, so that it hides
  // nothing): the true one, hypothesized from a few landmarks, wins the
  // cells.
  segments = {FrontWall(scene, -0.2)};
  report =
      GrowPlanePolygons(GrowthOn(), scene.camera, scene.world_from_cam, {}, {},
                        Loader(scene), &segments, {Hypothesis(scene, 0.0)});
  ASSERT_EQ(report.hypotheses.size(), 1u);
  EXPECT_TRUE(report.hypotheses[0].confirmed);
  EXPECT_GE(report.hypotheses[0].cells_textured, 11);
  EXPECT_EQ(segments.size(), 2u);
}

// The room's left wall (y = 1.5) painted with horizontal bands, constant
// along x, seen by a robot driving along x 0.6 m from it: a surface off
// the wall's plane misregisters the views along x only, where the bands do
// not change (a skirting board, a wall's foot seen along a corridor).
TestScene BandedWallDrive() {
  TestSceneOptions o;
  o.layout = TestLayout::kRoom;
  for (int i = 0; i < 30; ++i) {
    o.room.base_poses.push_back({-0.5 + 0.05 * i, 0.9, 0.0});
  }
  o.num_frames = 30;
  TestScene scene = MakeTestScene(o);
  cv::Mat& texture = scene.map.planes[3].texture;  // u = x, v = z
  cv::RNG rng(3);
  for (int row = 0; row < texture.rows;) {
    const int band = rng.uniform(4, 14);  // 2-7 cm at 200 texels/m
    texture.rowRange(row, std::min(row + band, texture.rows))
        .setTo(cv::Scalar::all(rng.uniform(40, 220)));
    row += band;
  }
  const Renderer renderer(scene.map);
  for (size_t i = 0; i < scene.world_from_cam.size(); ++i) {
    scene.images.push_back(LiveImage(renderer, scene.camera,
                                     scene.world_from_cam[i], 1.0, 0.0, 2.0,
                                     o.seed + i));
  }
  return scene;
}

TEST(PlaneGrowth, TextureAlongTheParallaxProvesNoPlane) {
  const TestScene scene = BandedWallDrive();
  const TexturedPlane& wall = scene.map.planes[3];
  // A patch of the wall's plane 20 cm in front of it (towards the robot),
  // 1.2-1.6 m ahead of the start, low on the wall.
  PlaneSegment seg;
  seg.plane = wall.plane;
  seg.plane.offset -= 0.2;
  seg.frame = wall.frame;
  seg.frame.origin += 0.2 * wall.plane.normal;
  seg.polygon = {{2.2, 0.1}, {2.6, 0.1}, {2.6, 0.4}, {2.2, 0.4}};
  // Without the aperture test the bands correlate through the wrong plane
  // and it grows along them.
  PlaneGrowthOptions options = GrowthOn();
  options.aperture_test = false;
  std::vector<PlaneSegment> segments = {seg};
  PlaneGrowthReport report =
      GrowPlanePolygons(options, scene.camera, scene.world_from_cam, {}, {},
                        Loader(scene), &segments);
  EXPECT_GT(report.planes[0].cells_textured, 20);
  EXPECT_GT(report.planes[0].area_after_m2, 0.3);
  // With it, no banded cell counts as texture evidence.
  segments = {seg};
  report = GrowPlanePolygons(GrowthOn(), scene.camera, scene.world_from_cam,
                             {}, {}, Loader(scene), &segments);
  EXPECT_LE(report.planes[0].cells_textured, 2);
  EXPECT_LT(report.planes[0].area_after_m2, 0.15);
}

TEST(PlaneGrowth, ThePointsPolygonBehindAWallThatMeetsItIsLeftOut) {
  const TestScene scene = Room();
  // The floor's fitted polygon reaches 0.4 m past the front wall (x = 3),
  // as a wall-foot point misplaced along its rays would pull it; the wall
  // is a segment too. No view sees the floor there.
  const TexturedPlane& floor = scene.map.planes[0];  // u = x + 1, v = y + 1.5
  PlaneSegment floor_seg;
  floor_seg.id = 0;
  floor_seg.plane = floor.plane;
  floor_seg.frame = floor.frame;
  floor_seg.polygon = {{2.5, 0.8}, {4.4, 0.8}, {4.4, 2.2}, {2.5, 2.2}};
  PlaneSegment wall = FrontWall(scene, 0.0);
  wall.id = 1;
  std::vector<PlaneSegment> segments = {floor_seg, wall};
  PlaneGrowthReport report =
      GrowPlanePolygons(GrowthOn(), scene.camera, scene.world_from_cam, {}, {},
                        Loader(scene), &segments);
  ASSERT_EQ(report.planes.size(), 2u);
  const PlaneGrowthStats& f =
      report.planes[0].plane_id == 0 ? report.planes[0] : report.planes[1];
  EXPECT_GT(f.cells_hidden, 10);
  // Area beyond the wall, one cell of slack (m^2).
  const double c = f.cell_m;
  auto behind = [c](const Polygon2d& p) {
    return std::abs(PolygonArea(p)) * (1 - ShareInside(p, -1, 4 + c, -1, 4));
  };
  EXPECT_LT(behind(segments[0].polygon), 0.05);
  // The points' polygon stays as it was, for localization.
  EXPECT_EQ(segments[0].landmark_polygon, floor_seg.polygon);
  // Kept, the floor goes on behind the wall.
  PlaneGrowthOptions keep = GrowthOn();
  keep.drop_hidden_cells = false;
  segments = {floor_seg, wall};
  GrowPlanePolygons(keep, scene.camera, scene.world_from_cam, {}, {},
                    Loader(scene), &segments);
  EXPECT_GT(behind(segments[0].polygon), 0.15);  // (0.4 m - a cell) x 1.4 m
  // A wall too small to trust (under min_occluder_cells of its own cells)
  // hides nothing.
  PlaneGrowthOptions strict = GrowthOn();
  strict.min_occluder_cells = 1e6;
  segments = {floor_seg, wall};
  report = GrowPlanePolygons(strict, scene.camera, scene.world_from_cam, {},
                             {}, Loader(scene), &segments);
  EXPECT_EQ(report.planes[0].cells_hidden + report.planes[1].cells_hidden, 0);
}

TEST(PlaneGrowth, PlainCellsOnlyBridgeAndLandmarksBehindCarveFreeSpace) {
  TestScene scene = Room();
  // Flat grey images: every cell is plain and consistent. By default plain
  // cells only fill between proofs (the patch, textured cells): none here,
  // so the polygon stays the patch.
  for (cv::Mat& img : scene.images) img.setTo(cv::Scalar::all(128));
  PlaneGrowthOptions options = GrowthOn();
  options.max_plain_run = 3;
  std::vector<PlaneSegment> segments = {FrontWallPatch(scene, 0.0)};
  PlaneGrowthReport report =
      GrowPlanePolygons(options, scene.camera, scene.world_from_cam, {}, {},
                        Loader(scene), &segments);
  EXPECT_EQ(report.planes[0].cells_textured, 0);
  EXPECT_EQ(report.planes[0].cells_plain, 0);
  EXPECT_NEAR(report.planes[0].area_after_m2, 0.12, 1e-9);
  // Without that rule growth goes exactly max_plain_run cells beyond the
  // patch in every direction.
  options.plain_between_proofs = false;
  segments = {FrontWallPatch(scene, 0.0)};
  report = GrowPlanePolygons(options, scene.camera, scene.world_from_cam, {},
                             {}, Loader(scene), &segments);
  const double c = report.planes[0].cell_m;
  EXPECT_EQ(report.planes[0].cells_textured, 0);
  Eigen::Vector2d lo, hi;
  PolygonBounds(segments[0].polygon, &lo, &hi);
  EXPECT_NEAR(lo.x(), 1.3 - 3 * c, 1.0 * c);
  EXPECT_NEAR(hi.x(), 1.7 + 3 * c, 1.0 * c);
  // Landmarks 15 cm behind the wall in two columns left of the patch,
  // seen from every frame: their rays cross the plane there, so it is
  // free space.
  std::vector<Landmark> landmarks;
  std::vector<Track> tracks;
  const TexturedPlane& wall = scene.map.planes[1];
  for (double s : {1.3 - 1.5 * c, 1.3 - 2.5 * c}) {
    for (double t = 0.15 - 4 * c; t < 0.45 + 4 * c; t += 0.02) {
      Landmark l;
      l.id = static_cast<FeatureId>(landmarks.size());
      l.x_in_world = wall.frame.ToWorld({s, t}) - 0.15 * wall.plane.normal;
      landmarks.push_back(l);
      Track track;
      track.id = l.id;
      for (int f = 0; f < 30; ++f) track.observations.push_back({f, {0, 0}});
      tracks.push_back(track);
    }
  }
  segments = {FrontWallPatch(scene, 0.0)};
  report = GrowPlanePolygons(options, scene.camera, scene.world_from_cam,
                             landmarks, tracks, Loader(scene), &segments);
  EXPECT_GT(report.planes[0].cells_carved, 3);
  PolygonBounds(segments[0].polygon, &lo, &hi);
  // The carved cells stop growth on the left, not on the right.
  EXPECT_GT(lo.x(), 1.3 - 1.5 * c);
  EXPECT_NEAR(hi.x(), 1.7 + 3 * c, 1.0 * c);
}

// Parallax proves a textured cell's plane; a plain cell's test (equal
// brightness) does not use it. With a parallax bar no view pair of the scene
// reaches, plain cells still join with min_plain_parallax_deg 0 and
// textured ones do not.
TEST(PlaneGrowth, PlainCellsNeedNoParallaxTexturedOnesDo) {
  PlaneGrowthOptions options = GrowthOn();
  options.max_plain_run = 3;
  options.plain_between_proofs = false;
  options.min_parallax_deg = 80.0;
  TestScene flat = Room();
  for (cv::Mat& img : flat.images) img.setTo(cv::Scalar::all(128));
  for (double plain_bar : {0.0, 80.0}) {
    options.min_plain_parallax_deg = plain_bar;
    std::vector<PlaneSegment> segments = {FrontWallPatch(flat, 0.0)};
    const PlaneGrowthReport report =
        GrowPlanePolygons(options, flat.camera, flat.world_from_cam, {}, {},
                          Loader(flat), &segments);
    if (plain_bar == 0.0) {
      // Exactly max_plain_run cells beyond the patch on either side.
      const double c = report.planes[0].cell_m;
      Eigen::Vector2d lo, hi;
      PolygonBounds(segments[0].polygon, &lo, &hi);
      EXPECT_GT(report.planes[0].cells_plain, 0);
      EXPECT_NEAR(lo.x(), 1.3 - 3 * c, 1.0 * c);
      EXPECT_NEAR(hi.x(), 1.7 + 3 * c, 1.0 * c);
    } else {
      EXPECT_EQ(report.planes[0].cells_plain, 0);
      EXPECT_NEAR(report.planes[0].area_after_m2, 0.12, 1e-9);
    }
  }
  // The textured wall: its textured cells join at the default bar, and not
  // without the parallax to place them.
  const TestScene textured = Room();
  options.min_plain_parallax_deg = 0.0;
  for (double bar : {PlaneGrowthOptions().min_parallax_deg, 80.0}) {
    options.min_parallax_deg = bar;
    std::vector<PlaneSegment> segments = {FrontWallPatch(textured, 0.0)};
    const PlaneGrowthReport report =
        GrowPlanePolygons(options, textured.camera, textured.world_from_cam, {},
                          {}, Loader(textured), &segments);
    if (bar == 80.0) {
      EXPECT_EQ(report.planes[0].cells_textured, 0);
    } else {
      EXPECT_GT(report.planes[0].cells_textured, 10);
    }
  }
}

// Auto-exposure brightens and darkens whole frames. Flat grey frames
// alternately 20 % darker and brighter than their median: plain cells
// agree across the views only once each view's gain, estimated from the
// tracked features' surroundings, is divided out.
TEST(PlaneGrowth, ExposureChangesBetweenViewsAreCompensated) {
  TestScene scene = Room();
  for (size_t f = 0; f < scene.images.size(); ++f) {
    scene.images[f].setTo(cv::Scalar::all(f % 2 == 0 ? 100 : 150));
  }
  std::vector<Track> tracks(30);
  for (int i = 0; i < 30; ++i) {
    tracks[i].id = static_cast<FeatureId>(i);
    for (int f = 0; f < 30; ++f) {
      tracks[i].observations.push_back({f, {50.0 + 10 * i, 100.0}});
    }
  }
  PlaneGrowthOptions options = GrowthOn();
  options.max_plain_run = 3;
  options.plain_between_proofs = false;
  for (bool compensate : {false, true}) {
    options.compensate_exposure = compensate;
    std::vector<PlaneSegment> segments = {FrontWallPatch(scene, 0.0)};
    const PlaneGrowthReport report =
        GrowPlanePolygons(options, scene.camera, scene.world_from_cam, {},
                          tracks, Loader(scene), &segments);
    if (compensate) {
      EXPECT_NEAR(report.min_exposure_gain, 0.8, 0.01);
      EXPECT_NEAR(report.max_exposure_gain, 1.2, 0.01);
      EXPECT_GT(report.planes[0].cells_plain, 20);
    } else {
      EXPECT_EQ(report.min_exposure_gain, 1.0);
      EXPECT_EQ(report.max_exposure_gain, 1.0);
      EXPECT_EQ(report.planes[0].cells_plain, 0);
    }
  }
}

TEST(PlaneGrowth, DisabledLeavesThePolygons) {
  const TestScene scene = Room();
  std::vector<PlaneSegment> segments = {FrontWallPatch(scene, 0.0)};
  const Polygon2d before = segments[0].polygon;
  PlaneGrowthOptions off;
  off.enabled = false;
  const PlaneGrowthReport report =
      GrowPlanePolygons(off, scene.camera,
                        scene.world_from_cam, {}, {}, Loader(scene), &segments);
  EXPECT_TRUE(report.planes.empty());
  EXPECT_EQ(segments[0].polygon, before);
  EXPECT_TRUE(segments[0].landmark_polygon.empty());
}

TEST(PlaneGrowth, OptionsAreChecked) {
  PlaneGrowthOptions o;
  o.cell_px = 0;
  EXPECT_THROW(o.Check(), OptionsError);
  o = PlaneGrowthOptions();
  o.min_views = 1;
  EXPECT_THROW(o.Check(), OptionsError);
  o = PlaneGrowthOptions();
  o.min_ncc = 1.0;
  EXPECT_THROW(o.Check(), OptionsError);
  o = PlaneGrowthOptions();
  o.min_plain_parallax_deg = -1.0;
  EXPECT_THROW(o.Check(), OptionsError);
}

}  // namespace
}  // namespace monomap
