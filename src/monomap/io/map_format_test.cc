#include "monomap/io/map_format.h"

#include <gtest/gtest.h>

#include <fstream>
#include <random>

#include <nlohmann/json.hpp>

#include "monomap/util/error.h"
#include "monomap/util/file.h"

namespace monomap {
namespace {
namespace fs = std::filesystem;
using nlohmann::json;

cv::Mat RandomTexture(int width, int height, unsigned seed) {
  cv::Mat texture(height, width, CV_8UC4);
  cv::RNG rng(seed);
  rng.fill(texture, cv::RNG::UNIFORM, 0, 256);
  // A transparent corner, as where no image saw the plane.
  texture(cv::Rect(0, 0, width / 3, height / 3))
      .forEach<cv::Vec4b>([](cv::Vec4b& p, const int*) { p[3] = 0; });
  return texture;
}

// Two planes: the ground z = 0 and a tilted wall, 12 landmarks, 6 poses.
Map MakeTestMap() {
  Map map;
  map.camera.width = 752;
  map.camera.height = 480;
  map.camera.fx = 458.654;
  map.camera.fy = 457.296;
  map.camera.cx = 367.215;
  map.camera.cy = 248.375;
  map.camera.distortion = {-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05,
                           0.0};

  TexturedPlane ground;
  ground.id = 0;
  ground.plane.normal = Eigen::Vector3d::UnitZ();
  ground.plane.offset = 0.0;
  ground.frame = MakePlaneFrame(ground.plane, {0.5, -0.25, 0.3}, {1, 0, 0});
  ground.pixels_per_meter = 100;
  ground.texture = RandomTexture(40, 30, 1);
  ground.polygon = {{0, 0}, {0.4, 0}, {0.4, 0.3}, {0, 0.3}};
  ground.features = {{17, {0.6, -0.2, 0}, {9.5, 4.5}},
                     {23, {0.8, 0.0, 0}, {29.5, 24.5}}};

  TexturedPlane wall;
  wall.id = 3;
  wall.plane.normal = Eigen::Vector3d(-1, 0.2, 0.1).normalized();
  wall.plane.offset = 2.0 / 3.0;
  wall.frame = MakePlaneFrame(wall.plane, {2, 1, 0.5}, {0, 1, 0});
  wall.pixels_per_meter = 64.5;
  wall.texture = RandomTexture(33, 17, 2);
  wall.polygon = {{0, 0}, {0.5, 0}, {0.5, 0.1}, {0.1, 0.1}, {0.1, 0.25},
                  {0, 0.25}};
  // Grown: the part its landmarks support.
  wall.landmark_polygon = {{0, 0}, {0.5, 0}, {0.5, 0.1}, {0, 0.1}};
  wall.features = {{5, wall.frame.ToWorld({0.05, 0.2}),
                    wall.TextureFromWorld(wall.frame.ToWorld({0.05, 0.2}))}};
  map.planes = {ground, wall};

  std::mt19937 rng(11);
  std::uniform_real_distribution<double> x(-3, 3);
  for (int i = 0; i < 12; ++i) {
    Landmark l;
    l.id = 100 + i;
    l.x_in_world = {x(rng), x(rng), x(rng)};
    l.color = Eigen::Vector3f(i * 20, 255 - i, 7);
    l.plane_id = i % 3 == 0 ? -1 : (i % 3 == 1 ? 0 : 3);
    l.num_observations = 3 + 5 * i;
    l.mean_reprojection_error_px = 0.125 * i;  // exact in float
    l.triangulation_angle_deg = 1.5 + 0.25 * i;
    map.landmarks.push_back(l);
  }
  for (int i = 0; i < 6; ++i) {
    TimedPose p;
    p.timestamp = 1.5 + 0.1 * i;
    p.world_from_cam = Rigid3d(YawRotation(0.2 * i) *
                                   Eigen::Quaterniond(Eigen::AngleAxisd(
                                       -2.0, Eigen::Vector3d::UnitX())),
                               {0.1 * i, -0.05 * i, 0.4});
    map.trajectory.push_back(p);
  }
  return map;
}

fs::path WriteTestMap(const std::string& name, const Map& map = MakeTestMap()) {
  const fs::path dir = fs::temp_directory_path() / ("monomap_map_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  WriteMap(dir, map);
  return dir;
}

json LoadJson(const fs::path& dir) {
  return json::parse(ReadFileToString(dir / "map.json"));
}
void SaveJson(const fs::path& dir, const json& j) {
  std::ofstream(dir / "map.json") << j.dump(1);
}

// ReadMap must throw InputError whose message holds every needle.
void ExpectMapError(const fs::path& dir,
                    const std::vector<std::string>& needles) {
  try {
    ReadMap(dir);
    FAIL() << "no error reading " << dir;
  } catch (const InputError& e) {
    for (const auto& needle : needles) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos)
          << "message '" << e.what() << "' lacks '" << needle << "'";
    }
  }
}

TEST(MapFormatTest, RoundTripKeepsEveryField) {
  const Map map = MakeTestMap();
  const fs::path dir = WriteTestMap("round_trip", map);
  for (const char* file : {"map.json", "plane_0.png", "plane_3.png",
                           "points.ply", "trajectory.txt", "map.glb"}) {
    EXPECT_TRUE(fs::is_regular_file(dir / file)) << file;
  }
  const json j = LoadJson(dir);
  EXPECT_EQ(j["format"], "monomap.map");
  EXPECT_EQ(j["version"], 1);
  EXPECT_EQ(j["planes"][1]["texture"], "plane_3.png");
  EXPECT_EQ(j["num_landmarks"], 12);
  EXPECT_EQ(j["num_frames"], 6);

  const Map read = ReadMap(dir);
  EXPECT_EQ(read.camera.width, map.camera.width);
  EXPECT_EQ(read.camera.height, map.camera.height);
  EXPECT_EQ(read.camera.fx, map.camera.fx);
  EXPECT_EQ(read.camera.fy, map.camera.fy);
  EXPECT_EQ(read.camera.cx, map.camera.cx);
  EXPECT_EQ(read.camera.cy, map.camera.cy);
  EXPECT_EQ(read.camera.distortion, map.camera.distortion);

  ASSERT_EQ(read.planes.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    const TexturedPlane& a = map.planes[i];
    const TexturedPlane& b = read.planes[i];
    EXPECT_EQ(b.id, a.id);
    // JSON numbers round-trip doubles exactly.
    EXPECT_EQ(b.plane.normal, a.plane.normal);
    EXPECT_EQ(b.plane.offset, a.plane.offset);
    EXPECT_EQ(b.frame.origin, a.frame.origin);
    EXPECT_EQ(b.frame.u_axis, a.frame.u_axis);
    EXPECT_EQ(b.frame.v_axis, a.frame.v_axis);
    EXPECT_EQ(b.pixels_per_meter, a.pixels_per_meter);
    EXPECT_EQ(b.polygon, a.polygon);
    EXPECT_EQ(b.landmark_polygon, a.landmark_polygon);
    EXPECT_EQ(j["planes"][i].contains("landmark_polygon"),
              !a.landmark_polygon.empty());
    ASSERT_EQ(b.features.size(), a.features.size());
    for (size_t k = 0; k < a.features.size(); ++k) {
      EXPECT_EQ(b.features[k].id, a.features[k].id);
      EXPECT_EQ(b.features[k].x_in_world, a.features[k].x_in_world);
      EXPECT_EQ(b.features[k].texture_px, a.features[k].texture_px);
    }
    ASSERT_EQ(b.texture.type(), CV_8UC4);
    ASSERT_EQ(b.texture.size(), a.texture.size());
    EXPECT_EQ(cv::norm(a.texture, b.texture, cv::NORM_INF), 0.0);
  }

  ASSERT_EQ(read.trajectory.size(), map.trajectory.size());
  for (size_t i = 0; i < map.trajectory.size(); ++i) {
    EXPECT_NEAR(read.trajectory[i].timestamp, map.trajectory[i].timestamp,
                1e-6);
    EXPECT_LT((read.trajectory[i].world_from_cam.translation -
               map.trajectory[i].world_from_cam.translation)
                  .norm(),
              1e-8);
    EXPECT_LT(AngleBetween(read.trajectory[i].world_from_cam.rotation,
                           map.trajectory[i].world_from_cam.rotation),
              1e-8);
  }

  ASSERT_EQ(read.landmarks.size(), map.landmarks.size());
  for (size_t i = 0; i < map.landmarks.size(); ++i) {
    EXPECT_EQ(read.landmarks[i].id, map.landmarks[i].id);
    EXPECT_EQ(read.landmarks[i].plane_id, map.landmarks[i].plane_id);
    EXPECT_EQ(read.landmarks[i].color, map.landmarks[i].color);
    EXPECT_EQ(read.landmarks[i].num_observations,
              map.landmarks[i].num_observations);
    EXPECT_EQ(read.landmarks[i].mean_reprojection_error_px,
              map.landmarks[i].mean_reprojection_error_px);
    EXPECT_EQ(read.landmarks[i].triangulation_angle_deg,
              map.landmarks[i].triangulation_angle_deg);
    EXPECT_LT((read.landmarks[i].x_in_world - map.landmarks[i].x_in_world)
                  .norm(),
              1e-6);  // stored as float
  }
}

TEST(MapFormatTest, LandmarksAreOptionalAndEmptyMapsWork) {
  fs::path dir = WriteTestMap("no_points");
  fs::remove(dir / "points.ply");
  const Map read = ReadMap(dir);
  EXPECT_TRUE(read.landmarks.empty());
  EXPECT_EQ(read.planes.size(), 2u);

  Map empty;
  empty.camera = MakeTestMap().camera;
  dir = WriteTestMap("empty", empty);
  const Map read_empty = ReadMap(dir);
  EXPECT_TRUE(read_empty.planes.empty());
  EXPECT_TRUE(read_empty.trajectory.empty());
  EXPECT_TRUE(read_empty.landmarks.empty());
}

TEST(MapFormatTest, EquidistantLensRoundTrips) {
  EXPECT_FALSE(LoadJson(WriteTestMap("plumb_bob"))["camera"].contains("model"))
      << "plumb_bob maps keep their old form";
  Map map = MakeTestMap();
  map.camera.model = LensModel::kEquidistant;
  map.camera.distortion = {0.02, -0.004, 0.001, -0.0002, 0.0};
  const fs::path dir = WriteTestMap("fisheye", map);
  EXPECT_EQ(LoadJson(dir)["camera"]["model"], "equidistant");
  const Map read = ReadMap(dir);
  EXPECT_EQ(read.camera.model, LensModel::kEquidistant);
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(read.camera.distortion[i], map.camera.distortion[i]) << i;
  }
}

// A map whose lens bundle adjustment refined keeps the calibration it was
// built from (given_camera, with its lens model); maps without one do not
// write the field.
TEST(MapFormatTest, GivenCameraRoundTrips) {
  EXPECT_FALSE(LoadJson(WriteTestMap("no_given")).contains("given_camera"));
  Map map = MakeTestMap();
  map.camera.model = LensModel::kEquidistant;
  map.given_camera = map.camera;
  map.given_camera->fx *= 1.01;
  map.given_camera->distortion[0] = 0.05;
  const Map read = ReadMap(WriteTestMap("given", map));
  ASSERT_TRUE(read.given_camera.has_value());
  EXPECT_EQ(read.given_camera->model, LensModel::kEquidistant);
  EXPECT_EQ(read.given_camera->fx, map.given_camera->fx);
  EXPECT_EQ(read.given_camera->distortion, map.given_camera->distortion);
  EXPECT_EQ(read.camera.fx, map.camera.fx);
}

TEST(MapFormatTest, WriteRejectsUnwritableMaps) {
  Map map = MakeTestMap();
  map.planes[1].texture = cv::Mat();
  const fs::path dir = fs::temp_directory_path() / "monomap_map_unwritable";
  fs::create_directories(dir);
  EXPECT_THROW(WriteMap(dir, map), OutputError);
  EXPECT_THROW(WriteMap(dir / "does_not_exist", MakeTestMap()), OutputError);
}

TEST(MapFormatTest, MissingAndInvalidFiles) {
  fs::path dir = WriteTestMap("missing_json");
  fs::remove(dir / "map.json");
  ExpectMapError(dir, {"map.json", "missing"});

  dir = WriteTestMap("truncated_json");
  const std::string text = ReadFileToString(dir / "map.json");
  std::ofstream(dir / "map.json") << text.substr(0, text.size() / 2);
  ExpectMapError(dir, {"map.json", "invalid JSON"});

  dir = WriteTestMap("missing_texture");
  fs::remove(dir / "plane_3.png");
  ExpectMapError(dir, {"map.json: field 'planes[1].texture'", "plane_3.png",
                       "missing"});

  dir = WriteTestMap("bad_texture");
  std::ofstream(dir / "plane_0.png") << "not a png";
  ExpectMapError(dir, {"plane_0.png", "cannot decode"});

  dir = WriteTestMap("missing_trajectory");
  fs::remove(dir / "trajectory.txt");
  ExpectMapError(dir, {"trajectory.txt", "missing"});
}

TEST(MapFormatTest, InvalidFieldsAreNamed) {
  struct Case {
    std::string name;
    std::function<void(json&)> edit;
    std::vector<std::string> needles;
  };
  const std::vector<Case> cases = {
      {"format", [](json& j) { j["format"] = "monomap.mesh"; },
       {"map.json: field 'format'", "monomap.mesh"}},
      {"version2", [](json& j) { j["version"] = 2; },
       {"map.json: field 'version'", "unsupported version 2"}},
      {"version_string", [](json& j) { j["version"] = "1"; },
       {"field 'version'", "integer"}},
      {"no_normal", [](json& j) { j["planes"][1].erase("normal"); },
       {"map.json: field 'planes[1].normal': missing"}},
      {"long_normal",
       [](json& j) { j["planes"][0]["normal"] = {0.0, 0.0, 1.01}; },
       {"map.json: field 'planes[0].normal'", "unit length"}},
      {"short_normal", [](json& j) { j["planes"][0]["normal"] = {0.0, 1.0}; },
       {"field 'planes[0].normal'", "expected 3 numbers, got 2"}},
      {"u_off_plane",
       [](json& j) { j["planes"][0]["u_axis"] = {0.0, 0.6, 0.8}; },
       {"field 'planes[0].u_axis'", "not in the plane"}},
      {"v_not_orthogonal",
       [](json& j) {
         const double s = std::sqrt(0.5);
         j["planes"][0]["u_axis"] = {1.0, 0.0, 0.0};
         j["planes"][0]["v_axis"] = {s, s, 0.0};
       },
       {"field 'planes[0].v_axis'", "not orthogonal"}},
      {"origin_off_plane",
       [](json& j) { j["planes"][0]["origin"] = {0.0, 0.0, 0.01}; },
       {"field 'planes[0].origin'", "not on the plane"}},
      {"zero_ppm", [](json& j) { j["planes"][1]["pixels_per_meter"] = 0; },
       {"field 'planes[1].pixels_per_meter'", "positive"}},
      {"bad_polygon",
       [](json& j) { j["planes"][1]["polygon"][2] = {0.5, "x"}; },
       {"field 'planes[1].polygon[2][1]'", "expected a number"}},
      {"short_landmark_polygon",
       [](json& j) { j["planes"][0]["landmark_polygon"] = {{0, 0}, {1, 0}}; },
       {"field 'planes[0].landmark_polygon'", "at least 3 vertices"}},
      {"bad_feature",
       [](json& j) { j["planes"][0]["features"][1]["xyz"] = {1, 2, 3, 4}; },
       {"field 'planes[0].features[1].xyz'", "expected 3 numbers"}},
      {"feature_id",
       [](json& j) { j["planes"][0]["features"][0]["id"] = 1.5; },
       {"field 'planes[0].features[0].id'", "integer"}},
      {"texture_path",
       [](json& j) { j["planes"][0]["texture"] = "../plane_0.png"; },
       {"field 'planes[0].texture'", "plain file name"}},
      {"duplicate_id", [](json& j) { j["planes"][1]["id"] = 0; },
       {"field 'planes[1].id'", "duplicate"}},
      {"camera", [](json& j) { j["camera"]["fx"] = -1; },
       {"field 'camera.fx'", "positive"}},
      {"lens", [](json& j) { j["camera"]["model"] = "fov"; },
       {"field 'camera.model'", "'fov' is not supported"}},
      {"distortion", [](json& j) { j["camera"]["distortion"] = {0.1}; },
       {"field 'camera.distortion'", "expected 5"}},
      {"given_camera",
       [](json& j) {
         j["given_camera"] = j["camera"];
         j["given_camera"]["model"] = "fov";
       },
       {"field 'given_camera.model'", "'fov' is not supported"}},
      {"given_camera_fy",
       [](json& j) {
         j["given_camera"] = j["camera"];
         j["given_camera"]["fy"] = 0;
       },
       {"field 'given_camera.fy'", "positive"}},
      {"no_planes", [](json& j) { j.erase("planes"); },
       {"field 'planes': missing"}},
      {"num_frames", [](json& j) { j["num_frames"] = 5; },
       {"trajectory.txt", "num_frames is 5"}},
      {"num_landmarks", [](json& j) { j["num_landmarks"] = 13; },
       {"points.ply", "num_landmarks is 13"}},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const fs::path dir = WriteTestMap("field_" + c.name);
    json j = LoadJson(dir);
    c.edit(j);
    SaveJson(dir, j);
    ExpectMapError(dir, c.needles);
  }
}

}  // namespace
}  // namespace monomap
