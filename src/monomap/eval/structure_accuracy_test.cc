#include "monomap/eval/structure_accuracy.h"

#include <gtest/gtest.h>

#include <cmath>

#include "monomap/eval/report_json.h"
#include "monomap/util/angles.h"
#include "monomap/util/error.h"

namespace monomap {
namespace {

// A true plane: the rectangle origin + [0, w] * u + [0, h] * v.
TexturedPlane Rectangle(int id, const Eigen::Vector3d& origin,
                        const Eigen::Vector3d& u, const Eigen::Vector3d& v,
                        double w, double h) {
  TexturedPlane p;
  p.id = id;
  p.frame.origin = origin;
  p.frame.u_axis = u;
  p.frame.v_axis = v;
  p.plane.normal = u.cross(v);
  p.plane.offset = -p.plane.normal.dot(origin);
  p.polygon = {{0, 0}, {w, 0}, {w, h}, {0, h}};
  p.pixels_per_meter = 100;
  return p;
}

// A corner of a 4x4 m room: floor z = 0 (id 0), wall x = 4 (id 1) and
// wall y = 4 (id 2), 2.5 m high.
Map Truth() {
  Map truth;
  truth.planes.push_back(Rectangle(0, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, 4, 4));
  truth.planes.push_back(Rectangle(1, {4, 0, 0}, {0, 1, 0}, {0, 0, 1}, 4, 2.5));
  truth.planes.push_back(Rectangle(2, {0, 4, 0}, {1, 0, 0}, {0, 0, 1}, 4, 2.5));
  return truth;
}

// n x n landmarks on the true plane `p`, inside its polygon (10 cm from
// the edges), labelled `plane_id`, 2 m deep.
void AddLandmarks(const TexturedPlane& p, double w, double h, int n,
                  int plane_id, Map* map) {
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      Landmark l;
      l.id = static_cast<FeatureId>(map->landmarks.size());
      const Eigen::Vector2d st(0.1 + (w - 0.2) * i / (n - 1),
                               0.1 + (h - 0.2) * j / (n - 1));
      l.x_in_world = p.frame.ToWorld(st);
      l.mean_depth_m = 2.0;
      l.plane_id = plane_id;
      map->landmarks.push_back(l);
    }
  }
}

// A fitted plane with the given id, plane and (unused) frame.
TexturedPlane Fitted(int id, const Plane& plane) {
  TexturedPlane p;
  p.id = id;
  p.plane = plane;
  return p;
}

// The map of the room corner as it should be: floor and wall x = 4 fitted
// exactly with 100 landmarks each; wall y = 4 has 3x3 unlabelled landmarks
// (too few to be observed).
Map ExactMap(const Map& truth) {
  Map map;
  map.planes.push_back(Fitted(10, truth.planes[0].plane));
  map.planes.push_back(Fitted(11, truth.planes[1].plane));
  AddLandmarks(truth.planes[0], 4, 4, 10, 10, &map);
  AddLandmarks(truth.planes[1], 4, 2.5, 10, 11, &map);
  AddLandmarks(truth.planes[2], 4, 2.5, 3, -1, &map);
  return map;
}

// The plane through the world origin with `normal` (unit).
Plane ThroughOrigin(const Eigen::Vector3d& normal) {
  Plane p;
  p.normal = normal.normalized();
  p.offset = 0.0;
  return p;
}

TEST(StructureAccuracyTest, ExactMatchIsPerfect) {
  const Map truth = Truth();
  const Map map = ExactMap(truth);
  const StructureAccuracy a =
      EvaluateStructure(map, truth, Rigid3d::Identity(), {});
  EXPECT_EQ(a.true_planes, 3);
  EXPECT_EQ(a.observed_true_planes, 2);
  EXPECT_EQ(a.fitted_planes, 2);
  EXPECT_EQ(a.landmarks, 209);
  EXPECT_EQ(a.landmarks_off_structure, 0);
  EXPECT_DOUBLE_EQ(a.precision, 1.0);
  EXPECT_DOUBLE_EQ(a.recall, 1.0);
  EXPECT_EQ(a.point_error_all.absolute_m.count, 209u);
  EXPECT_NEAR(a.point_error_all.absolute_m.max, 0.0, 1e-12);
  EXPECT_NEAR(a.point_error_all.relative_percent.max, 0.0, 1e-10);
  EXPECT_EQ(a.point_error_on_planes.absolute_m.count, 200u);
  ASSERT_EQ(a.matches.size(), 2u);
  for (int k = 0; k < 2; ++k) {
    const PlaneMatch& m = a.matches[k];
    EXPECT_EQ(m.fitted_id, 10 + k);
    EXPECT_EQ(m.true_id, k);
    EXPECT_EQ(m.inliers, 100);
    EXPECT_NEAR(m.normal_error_deg, 0.0, 1e-6);
    EXPECT_NEAR(m.offset_error_m, 0.0, 1e-12);
    EXPECT_TRUE(m.matched);
  }
  EXPECT_NEAR(a.normal_error_deg.max, 0.0, 1e-6);
  EXPECT_NEAR(a.offset_error_m.max, 0.0, 1e-12);
  ASSERT_EQ(a.true_plane_results.size(), 3u);
  for (int j = 0; j < 2; ++j) {
    const TruePlaneResult& t = a.true_plane_results[j];
    EXPECT_EQ(t.true_id, j);
    EXPECT_EQ(t.near_landmarks, 100);
    EXPECT_TRUE(t.observed);
    EXPECT_TRUE(t.matched);
    EXPECT_EQ(t.best_fitted_id, 10 + j);
    EXPECT_NEAR(t.normal_error_deg, 0.0, 1e-6);
  }
  EXPECT_EQ(a.true_plane_results[2].near_landmarks, 9);
  EXPECT_FALSE(a.true_plane_results[2].observed);
  EXPECT_FALSE(a.true_plane_results[2].matched);
  EXPECT_EQ(a.true_plane_results[2].best_fitted_id, -1);
}

TEST(StructureAccuracyTest, TiltedPlaneReportsItsAngle) {
  const Map truth = Truth();
  for (double tilt_deg : {0.5, 1.5, 3.0}) {
    Map map = ExactMap(truth);
    // The fitted floor tilted about the x axis (through the origin, so the
    // offset stays 0); its inliers still lie on the true floor.
    map.planes[0].plane = ThroughOrigin(
        {0, -std::sin(DegToRad(tilt_deg)), std::cos(DegToRad(tilt_deg))});
    const StructureAccuracy a =
        EvaluateStructure(map, truth, Rigid3d::Identity(), {});
    const PlaneMatch& m = a.matches[0];
    EXPECT_EQ(m.true_id, 0);
    EXPECT_NEAR(m.normal_error_deg, tilt_deg, 1e-9);
    EXPECT_NEAR(m.offset_error_m, 0.0, 1e-12);
    EXPECT_NEAR(a.true_plane_results[0].normal_error_deg, tilt_deg, 1e-9);
    EXPECT_NEAR(a.normal_error_deg.max, tilt_deg, 1e-9);
    // Matched within the default 2 degrees only.
    const bool within = tilt_deg <= 2.0;
    EXPECT_EQ(m.matched, within) << tilt_deg;
    EXPECT_EQ(a.true_plane_results[0].matched, within);
    EXPECT_DOUBLE_EQ(a.precision, within ? 1.0 : 0.5);
    EXPECT_DOUBLE_EQ(a.recall, within ? 1.0 : 0.5);
  }
}

TEST(StructureAccuracyTest, OffsetIsMeasuredWhereThePlaneIs) {
  const Map truth = Truth();
  for (double tilt_deg : {1.5, 3.0}) {
    Map map = ExactMap(truth);
    // The fitted wall x = 4 turned about the vertical line through its
    // centre (4, 2, 1.25): at the world origin it is 2 sin(1.5 deg) = 5.2 cm
    // off, but it passes through the wall where the wall is.
    const Eigen::Vector3d center(4, 2, 1.25);
    const double t = DegToRad(tilt_deg);
    TexturedPlane& wall = map.planes[1];
    wall.plane.normal = {std::cos(t), std::sin(t), 0};
    wall.plane.offset = -wall.plane.normal.dot(center);
    wall.frame = MakePlaneFrame(wall.plane, center, {0, 0, 1});
    wall.polygon = {{-1, -2}, {1, -2}, {1, 2}, {-1, 2}};
    const StructureAccuracy a =
        EvaluateStructure(map, truth, Rigid3d::Identity(), {});
    const PlaneMatch& m = a.matches[1];
    EXPECT_EQ(m.true_id, 1);
    EXPECT_NEAR(m.normal_error_deg, tilt_deg, 1e-9);
    EXPECT_NEAR(m.offset_error_m, 0.0, 1e-12);
    EXPECT_EQ(m.matched, tilt_deg <= 2.0);
    // Moved 5 cm along its normal, the centre is 5 cm off: no match.
    wall.plane.offset -= 0.05;
    wall.frame.origin += 0.05 * wall.plane.normal;
    const StructureAccuracy moved =
        EvaluateStructure(map, truth, Rigid3d::Identity(), {});
    EXPECT_NEAR(moved.matches[1].offset_error_m, 0.05 * std::cos(t), 1e-9);
    EXPECT_FALSE(moved.matches[1].matched);
  }
}

TEST(StructureAccuracyTest, OrientationOfTheNormalDoesNotMatter) {
  const Map truth = Truth();
  Map map = ExactMap(truth);
  map.planes[1].plane.normal = -map.planes[1].plane.normal;
  map.planes[1].plane.offset = -map.planes[1].plane.offset;
  const StructureAccuracy a =
      EvaluateStructure(map, truth, Rigid3d::Identity(), {});
  EXPECT_NEAR(a.matches[1].normal_error_deg, 0.0, 1e-6);
  EXPECT_NEAR(a.matches[1].offset_error_m, 0.0, 1e-12);
  EXPECT_TRUE(a.matches[1].matched);
}

TEST(StructureAccuracyTest, PlaneOffTheStructureLowersPrecision) {
  const Map truth = Truth();
  Map map = ExactMap(truth);
  // A spurious horizontal plane 1.2 m above the floor, with 36 landmarks
  // floating over it: they count against the floor (their projection is
  // on it), so the plane is compared with the floor and misses it by
  // 1.2 m.
  Plane floating = ThroughOrigin({0, 0, 1});
  floating.offset = -1.2;
  map.planes.push_back(Fitted(12, floating));
  TexturedPlane above = truth.planes[0];
  above.frame.origin = {1, 1, 1.2};
  AddLandmarks(above, 1.2, 1.2, 6, 12, &map);
  const StructureAccuracy a =
      EvaluateStructure(map, truth, Rigid3d::Identity(), {});
  ASSERT_EQ(a.matches.size(), 3u);
  EXPECT_EQ(a.matches[2].fitted_id, 12);
  EXPECT_EQ(a.matches[2].inliers, 36);
  EXPECT_EQ(a.matches[2].true_id, 0);
  EXPECT_NEAR(a.matches[2].offset_error_m, 1.2, 1e-12);
  EXPECT_FALSE(a.matches[2].matched);
  EXPECT_DOUBLE_EQ(a.precision, 2.0 / 3.0);
  // The floor is still found by the good fitted plane.
  EXPECT_DOUBLE_EQ(a.recall, 1.0);
  EXPECT_EQ(a.true_plane_results[0].best_fitted_id, 10);
  // The floating points are the large point errors.
  EXPECT_NEAR(a.point_error_all.absolute_m.max, 1.2, 1e-12);
  EXPECT_NEAR(a.point_error_all.relative_percent.max, 60.0, 1e-9);
}

TEST(StructureAccuracyTest, PlaneWithNoInlierOnTheStructureTakesClosest) {
  const Map truth = Truth();
  Map map = ExactMap(truth);
  // Landmarks above the room and outside every polygon: off the structure.
  // Their plane (x = 4.1) is compared with the closest true plane, the
  // wall x = 4.
  Plane outside = ThroughOrigin({1, 0, 0});
  outside.offset = -4.1;
  map.planes.push_back(Fitted(12, outside));
  TexturedPlane high = truth.planes[1];
  high.frame.origin = {4.1, 0, 3.0};
  AddLandmarks(high, 4, 1, 5, 12, &map);
  const StructureAccuracy a =
      EvaluateStructure(map, truth, Rigid3d::Identity(), {});
  EXPECT_EQ(a.landmarks_off_structure, 25);
  EXPECT_EQ(a.point_error_all.absolute_m.count, 209u);
  EXPECT_EQ(a.matches[2].inliers, 25);
  EXPECT_EQ(a.matches[2].true_id, 1);
  EXPECT_NEAR(a.matches[2].offset_error_m, 0.1, 1e-12);
  EXPECT_FALSE(a.matches[2].matched);
  EXPECT_DOUBLE_EQ(a.precision, 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(a.recall, 1.0);
}

TEST(StructureAccuracyTest, UnobservedTruePlaneDoesNotCountAgainstRecall) {
  const Map truth = Truth();
  Map map = ExactMap(truth);  // wall y = 4 has 9 landmarks: unobserved
  StructureAccuracy a = EvaluateStructure(map, truth, Rigid3d::Identity(), {});
  EXPECT_EQ(a.observed_true_planes, 2);
  EXPECT_DOUBLE_EQ(a.recall, 1.0);
  // With 36 landmarks on it, it is observed, and missing it costs recall.
  AddLandmarks(truth.planes[2], 4, 2.5, 6, -1, &map);
  a = EvaluateStructure(map, truth, Rigid3d::Identity(), {});
  EXPECT_EQ(a.observed_true_planes, 3);
  EXPECT_TRUE(a.true_plane_results[2].observed);
  EXPECT_FALSE(a.true_plane_results[2].matched);
  EXPECT_DOUBLE_EQ(a.recall, 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(a.precision, 1.0);
  // The threshold is an option.
  StructureAccuracyOptions o;
  o.min_observed_landmarks = 50;
  a = EvaluateStructure(map, truth, Rigid3d::Identity(), o);
  EXPECT_EQ(a.observed_true_planes, 2);
  EXPECT_DOUBLE_EQ(a.recall, 1.0);
}

TEST(StructureAccuracyTest, BestOfSeveralFittedPlanesPerTruePlane) {
  const Map truth = Truth();
  Map map = ExactMap(truth);
  map.planes[0].plane =
      ThroughOrigin({0, -std::sin(DegToRad(1.0)), std::cos(DegToRad(1.0))});
  // A second, better segment of the floor, and a third that misses it.
  map.planes.push_back(Fitted(12, ThroughOrigin({std::sin(DegToRad(0.25)), 0,
                                                 std::cos(DegToRad(0.25))})));
  map.planes.push_back(Fitted(13, ThroughOrigin({std::sin(DegToRad(0.1)), 0,
                                                 std::cos(DegToRad(0.1))})));
  map.planes.back().plane.offset = 0.05;  // 5 cm off: no match
  for (int k = 0; k < 20; ++k) map.landmarks[k].plane_id = 12;
  for (int k = 20; k < 40; ++k) map.landmarks[k].plane_id = 13;
  const StructureAccuracy a =
      EvaluateStructure(map, truth, Rigid3d::Identity(), {});
  const TruePlaneResult& floor = a.true_plane_results[0];
  EXPECT_TRUE(floor.matched);
  EXPECT_EQ(floor.best_fitted_id, 12);
  EXPECT_NEAR(floor.normal_error_deg, 0.25, 1e-9);
  EXPECT_DOUBLE_EQ(a.precision, 3.0 / 4.0);
  EXPECT_EQ(a.normal_error_deg.count, 4u);
}

TEST(StructureAccuracyTest, TruthFromMapIsApplied) {
  const Map truth = Truth();
  const Map exact = ExactMap(truth);
  // The same map in a frame rotated by 30 degrees and shifted.
  const Eigen::AngleAxisd rotation(DegToRad(30), Eigen::Vector3d::UnitZ());
  const Rigid3d map_from_truth(Eigen::Quaterniond(rotation),
                               Eigen::Vector3d(0.5, -1.0, 0.2));
  Map map = exact;
  for (auto& l : map.landmarks) l.x_in_world = map_from_truth * l.x_in_world;
  for (auto& p : map.planes) p.plane = p.plane.Transformed(map_from_truth);
  const StructureAccuracy a =
      EvaluateStructure(map, truth, map_from_truth.Inverse(), {});
  EXPECT_DOUBLE_EQ(a.precision, 1.0);
  EXPECT_DOUBLE_EQ(a.recall, 1.0);
  EXPECT_NEAR(a.point_error_all.absolute_m.max, 0.0, 1e-9);
  EXPECT_NEAR(a.normal_error_deg.max, 0.0, 1e-5);
  EXPECT_NEAR(a.offset_error_m.max, 0.0, 1e-9);
  // Without the transform the map misses the structure.
  const StructureAccuracy b =
      EvaluateStructure(map, truth, Rigid3d::Identity(), {});
  EXPECT_LT(b.precision, 1.0);
  EXPECT_GT(b.point_error_all.absolute_m.median, 0.1);
}

TEST(StructureAccuracyTest, ScaledMapUndoesAnOdometryScaleError) {
  const Map truth = Truth();
  // The map a 3 % wheel-radius error builds: everything 1.03x as far from
  // the world origin (where the odometry starts).
  Map map = ScaledMap(ExactMap(truth), 1.03);
  for (TexturedPlane& p : map.planes) {
    p.frame = MakePlaneFrame(p.plane, {1, 1, 1}, {0, 0, 1});
    p.polygon = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    p.landmark_polygon = {{0, 0}, {0.5, 0}, {0.5, 1}, {0, 1}};
    p.pixels_per_meter = 100;
  }
  map.trajectory.push_back({0.0, Rigid3d::Identity()});
  map.trajectory.back().world_from_cam.translation = {1, 2, 3};
  const StructureAccuracy off =
      EvaluateStructure(map, truth, Rigid3d::Identity(), {});
  EXPECT_GT(off.point_error_all.absolute_m.median, 0.03);
  const Map back = ScaledMap(map, 1.0 / 1.03);
  const StructureAccuracy a =
      EvaluateStructure(back, truth, Rigid3d::Identity(), {});
  EXPECT_NEAR(a.point_error_all.absolute_m.max, 0.0, 1e-9);
  EXPECT_NEAR(a.offset_error_m.max, 0.0, 1e-9);
  EXPECT_DOUBLE_EQ(a.precision, 1.0);
  // A texture pixel shows the scaled point; depths and poses scale too.
  const Eigen::Vector2d px(37, 12);
  EXPECT_NEAR((back.planes[1].WorldFromTexture(px) -
               map.planes[1].WorldFromTexture(px) / 1.03)
                  .norm(),
              0.0, 1e-12);
  // Both outlines scale with the plane (a grown plane's supported part too).
  EXPECT_NEAR(back.planes[1].polygon[2].x(), 1 / 1.03, 1e-12);
  EXPECT_NEAR(back.planes[1].landmark_polygon[1].x(), 0.5 / 1.03, 1e-12);
  EXPECT_NEAR(back.landmarks[0].mean_depth_m, 2.0, 1e-12);
  EXPECT_NEAR(back.trajectory[0].world_from_cam.translation.z(), 3 / 1.03,
              1e-12);
}

TEST(StructureAccuracyTest, PolygonMargin) {
  Map truth;
  truth.planes.push_back(Rectangle(0, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, 4, 4));
  Map map;
  Landmark l;
  l.x_in_world = {2.0, -0.02, 0.004};  // 2 cm outside the floor, 4 mm up
  l.mean_depth_m = 2.0;
  map.landmarks.push_back(l);
  StructureAccuracy a = EvaluateStructure(map, truth, Rigid3d::Identity(), {});
  EXPECT_EQ(a.landmarks_off_structure, 0);
  EXPECT_NEAR(a.point_error_all.absolute_m.max, 0.004, 1e-12);
  EXPECT_NEAR(a.point_error_all.relative_percent.max, 0.2, 1e-9);
  StructureAccuracyOptions o;
  o.polygon_margin_m = 0.01;
  a = EvaluateStructure(map, truth, Rigid3d::Identity(), o);
  EXPECT_EQ(a.landmarks_off_structure, 1);
  EXPECT_EQ(a.point_error_all.absolute_m.count, 0u);
  // No fitted plane: precision 0; no observed true plane: recall 0.
  EXPECT_EQ(a.precision, 0.0);
  EXPECT_EQ(a.recall, 0.0);
}

TEST(StructureAccuracyTest, CheckRejectsBadOptions) {
  EXPECT_NO_THROW(StructureAccuracyOptions().Check());
  StructureAccuracyOptions o;
  o.max_match_angle_deg = 0;
  EXPECT_THROW(o.Check(), OptionsError);
  o = {};
  o.max_match_angle_deg = std::nan("");
  EXPECT_THROW(o.Check(), OptionsError);
  o = {};
  o.max_match_offset_m = -0.01;
  EXPECT_THROW(o.Check(), OptionsError);
  o = {};
  o.polygon_margin_m = -0.001;
  EXPECT_THROW(o.Check(), OptionsError);
  o = {};
  o.polygon_margin_m = 0;  // allowed: polygons as they are
  EXPECT_NO_THROW(o.Check());
  o = {};
  o.min_observed_landmarks = 0;
  EXPECT_THROW(o.Check(), OptionsError);
  o = {};
  o.observed_distance_m = 0;
  EXPECT_THROW(o.Check(), OptionsError);
  // EvaluateStructure checks its options.
  o = {};
  o.max_match_offset_m = 0;
  EXPECT_THROW(EvaluateStructure(Map(), Truth(), Rigid3d::Identity(), o),
               OptionsError);
}

TEST(StructureAccuracyTest, LandmarkDepthsFromTracksOrNearestCamera) {
  Map map;
  for (int f = 0; f < 3; ++f) {  // cameras at x = 0, 1, 2
    TimedPose p;
    p.timestamp = f;
    p.world_from_cam.translation = Eigen::Vector3d(f, 0, 0);
    map.trajectory.push_back(p);
  }
  for (int i = 0; i < 3; ++i) {
    Landmark l;
    l.id = i;
    l.x_in_world = Eigen::Vector3d(0, 4, 0);
    map.landmarks.push_back(l);
  }
  auto seen_in = [](FeatureId id, std::vector<int> frames) {
    Track t;
    t.id = id;
    for (int f : frames) t.observations.push_back({f, Eigen::Vector2d::Zero()});
    return t;
  };
  const Track seen_by_0_and_2 = seen_in(0, {0, 2});  // 4 and sqrt(20) m
  // Frame 7 has no pose: the nearest camera instead.
  const Track beyond_trajectory = seen_in(1, {1, 7});
  // Landmark 2 has no track: nearest camera (x = 0) at 4 m.
  EXPECT_EQ(SetLandmarkDepths({seen_by_0_and_2, beyond_trajectory}, &map), 1);
  EXPECT_DOUBLE_EQ(map.landmarks[0].mean_depth_m, (4 + std::sqrt(20.0)) / 2);
  EXPECT_DOUBLE_EQ(map.landmarks[1].mean_depth_m, 4.0);
  EXPECT_DOUBLE_EQ(map.landmarks[2].mean_depth_m, 4.0);
  map.trajectory.clear();
  EXPECT_EQ(SetLandmarkDepths({}, &map), 0);
  EXPECT_EQ(map.landmarks[0].mean_depth_m, 0.0);
}

TEST(StructureAccuracyTest, JsonAndTable) {
  const Map truth = Truth();
  Map map = ExactMap(truth);
  map.planes[0].plane =
      ThroughOrigin({0, -std::sin(DegToRad(1.5)), std::cos(DegToRad(1.5))});
  const StructureAccuracy a =
      EvaluateStructure(map, truth, Rigid3d::Identity(), {});
  const nlohmann::json j = ToJson(a);
  EXPECT_EQ(j["counts"]["true_planes"].get<int>(), 3);
  EXPECT_EQ(j["counts"]["observed_true_planes"].get<int>(), 2);
  EXPECT_EQ(j["counts"]["fitted_planes"].get<int>(), 2);
  EXPECT_EQ(j["counts"]["landmarks"].get<int>(), 209);
  EXPECT_EQ(j["counts"]["landmarks_off_structure"].get<int>(), 0);
  EXPECT_EQ(
      j["point_error"]["all_landmarks"]["absolute_m"]["count"].get<size_t>(),
      209u);
  EXPECT_EQ(j["point_error"]["landmarks_on_planes"]["relative_percent"]["count"]
                .get<size_t>(),
            200u);
  ASSERT_EQ(j["planes"]["matches"].size(), 2u);
  const nlohmann::json& m = j["planes"]["matches"][0];
  EXPECT_EQ(m["fitted_id"].get<int>(), 10);
  EXPECT_EQ(m["inliers"].get<int>(), 100);
  EXPECT_EQ(m["true_id"].get<int>(), 0);
  EXPECT_NEAR(m["normal_error_deg"].get<double>(), 1.5, 1e-9);
  EXPECT_NEAR(m["offset_error_m"].get<double>(), 0.0, 1e-12);
  EXPECT_TRUE(m["matched"].get<bool>());
  EXPECT_NEAR(j["planes"]["normal_error_deg"]["max"].get<double>(), 1.5, 1e-9);
  EXPECT_TRUE(j["planes"].contains("offset_error_m"));
  EXPECT_DOUBLE_EQ(j["planes"]["precision"].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(j["planes"]["recall"].get<double>(), 1.0);
  ASSERT_EQ(j["true_planes"].size(), 3u);
  EXPECT_EQ(j["true_planes"][0]["true_id"].get<int>(), 0);
  EXPECT_EQ(j["true_planes"][0]["best_fitted_id"].get<int>(), 10);
  EXPECT_TRUE(j["true_planes"][0]["observed"].get<bool>());
  EXPECT_TRUE(j["true_planes"][0]["matched"].get<bool>());
  EXPECT_EQ(j["true_planes"][0]["near_landmarks"].get<int>(), 100);
  EXPECT_NEAR(j["true_planes"][0]["normal_error_deg"].get<double>(), 1.5, 1e-9);
  EXPECT_FALSE(j["true_planes"][2]["observed"].get<bool>());
  EXPECT_EQ(j["true_planes"][2]["best_fitted_id"].get<int>(), -1);
  EXPECT_TRUE(j["true_planes"][2]["normal_error_deg"].is_null());
  EXPECT_TRUE(j["true_planes"][2]["offset_error_m"].is_null());

  const std::string table = FormatTable(a);
  EXPECT_NE(table.find("precision 100.0%"), std::string::npos) << table;
  EXPECT_NE(table.find("recall 100.0%"), std::string::npos) << table;
  EXPECT_NE(table.find("1.500"), std::string::npos) << table;
  EXPECT_NE(table.find("all abs (mm)"), std::string::npos) << table;
  EXPECT_NE(table.find("on planes rel (%)"), std::string::npos) << table;
  EXPECT_EQ(table.back(), '\n');
}

}  // namespace
}  // namespace monomap
