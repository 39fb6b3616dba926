#include "monomap/report/report_data.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>

#include "monomap/io/dataset.h"
#include "monomap/io/feature_table.h"
#include "monomap/io/map_format.h"
#include "monomap/io/trajectory_io.h"
#include "monomap/report/localization_run.h"
#include "monomap/sim/simulate.h"
#include "monomap/util/error.h"
#include "monomap/util/file.h"

namespace monomap {
namespace {
namespace fs = std::filesystem;

TEST(Base64Test, Rfc4648Vectors) {
  EXPECT_EQ(Base64Encode(""), "");
  EXPECT_EQ(Base64Encode("f"), "Zg==");
  EXPECT_EQ(Base64Encode("fo"), "Zm8=");
  EXPECT_EQ(Base64Encode("foo"), "Zm9v");
  EXPECT_EQ(Base64Encode("foobar"), "Zm9vYmFy");
  EXPECT_EQ(Base64Encode(std::string("\xff\x00\x10", 3)), "/wAQ");
}

TEST(ReportOptionsTest, RejectsBadValues) {
  ReportOptions o;
  EXPECT_NO_THROW(o.Check());
  o.max_points = 0;
  EXPECT_THROW(o.Check(), OptionsError);
  o = ReportOptions();
  o.overlay_frames = -1;
  EXPECT_THROW(o.Check(), OptionsError);
  o.overlay_frames = 0;  // no overlays is fine
  EXPECT_NO_THROW(o.Check());
}

// A simulated dataset and a map "built" from it by hand, with figures
// known exactly: the map's trajectory is the ground truth drifting 1 cm
// per frame sideways, one plane whose texture covers the left half of its
// polygon, 4 of 10 points on that plane, tracks on every frame.
class ReportDataTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = new fs::path(fs::temp_directory_path() /
                         ("monomap_report_test_" + std::to_string(getpid())));
    fs::remove_all(*root_);
    SimulationOptions sim;
    sim.world = "lab-corner";
    sim.num_frames = 20;
    sim.width = 160;
    sim.height = 120;
    sim.show_progress = false;
    Simulate(sim, *root_ / "dataset");
  }
  static void TearDownTestSuite() {
    fs::remove_all(*root_);
    delete root_;
  }

  // Writes the map into root/name and returns its directory.
  static fs::path WriteTestMap(const std::string& name) {
    const Dataset d = LoadDataset(*root_ / "dataset");
    Map map;
    map.camera = d.camera;
    for (size_t i = 0; i < d.frames.size(); ++i) {
      Rigid3d pose = *d.frames[i].groundtruth_world_from_cam;
      pose.translation.y() += 0.01 * static_cast<double>(i);
      map.trajectory.push_back({d.frames[i].timestamp, pose});
    }
    TexturedPlane plane;
    plane.id = 0;
    plane.plane.normal = Eigen::Vector3d::UnitZ();
    plane.plane.offset = 0.0;
    plane.frame.origin = Eigen::Vector3d::Zero();
    plane.frame.u_axis = Eigen::Vector3d::UnitX();
    plane.frame.v_axis = Eigen::Vector3d::UnitY();
    plane.pixels_per_meter = 100.0;
    plane.polygon = {{0, 0}, {2, 0}, {2, 1}, {0, 1}};  // 200 x 100 texels
    plane.texture = cv::Mat(100, 200, CV_8UC4, cv::Scalar(90, 120, 150, 0));
    plane.texture.colRange(0, 100).setTo(cv::Scalar(90, 120, 150, 255));
    map.planes.push_back(plane);
    for (int i = 0; i < 10; ++i) {
      Landmark l;
      l.id = i;
      l.x_in_world = Eigen::Vector3d(0.1 * i, 0.5, i < 4 ? 0.0 : 1.0);
      l.plane_id = i < 4 ? 0 : -1;
      map.landmarks.push_back(l);
    }
    const fs::path dir = *root_ / name;
    fs::create_directories(dir);
    WriteMap(dir, map);
    std::vector<Track> tracks(2);
    for (int t = 0; t < 2; ++t) {
      tracks[t].id = t;
      for (int f = 0; f < 20; ++f) {
        tracks[t].observations.push_back({f, Eigen::Vector2d(10 + f, 20 + t)});
      }
    }
    WriteFeatureTable(dir / "features.csv", tracks);
    return dir;
  }
  static fs::path* root_;
};
fs::path* ReportDataTest::root_ = nullptr;

TEST_F(ReportDataTest, FiguresOfACompleteMap) {
  ReportInputs in;
  in.map_dir = WriteTestMap("map_ok");
  in.dataset_dir = *root_ / "dataset";
  in.command_line = "monomap report test";
  const ReportData r = BuildReportData(in);
  const nlohmann::json& j = r.json;
  EXPECT_TRUE(r.problems.empty());
  EXPECT_EQ(j["problems"].size(), 0u);
  for (const auto& f : j["map_files"]) EXPECT_EQ(f["status"], "ok") << f;
  EXPECT_EQ(j["map_files"].size(), 5u);
  EXPECT_EQ(j["provenance"]["command_line"], "monomap report test");
  EXPECT_EQ(j["provenance"]["inputs"]["dataset"], in.dataset_dir.string());

  // map.glb is embedded whole ("glTF" magic = "Z2xURg" in base64).
  EXPECT_EQ(j["glb_base64"].get<std::string>().rfind("Z2xURg", 0), 0u);
  const auto glb_bytes = fs::file_size(in.map_dir / "map.glb");
  EXPECT_EQ(j["glb_base64"].get<std::string>().size(), (glb_bytes + 2) / 3 * 4);

  ASSERT_EQ(j["planes"].size(), 1u);
  const nlohmann::json& p = j["planes"][0];
  EXPECT_EQ(p["width"], 200);
  EXPECT_EQ(p["height"], 100);
  EXPECT_EQ(p["points"], 4);
  EXPECT_NEAR(p["coverage"].get<double>(), 0.5, 0.02);
  EXPECT_FALSE(p["png_base64"].get<std::string>().empty());

  EXPECT_EQ(j["points"]["plane"].size(), 10u);
  EXPECT_EQ(j["points"]["xyz"].size(), 30u);
  EXPECT_EQ(j["points"]["plane"][0], 0);
  EXPECT_EQ(j["points"]["plane"][9], -1);
  EXPECT_DOUBLE_EQ(j["points"]["xyz"][27].get<double>(), 0.9);

  // Map, odometry and ground truth paths; the map's error grows by 1 cm a
  // frame after the first-pose alignment.
  ASSERT_EQ(j["trajectories"].size(), 3u);
  EXPECT_EQ(j["trajectories"][0]["name"], "map (refined)");
  EXPECT_EQ(j["trajectories"][2]["name"], "ground truth");
  EXPECT_EQ(j["trajectories"][0]["xyz"].size(), 60u);
  ASSERT_EQ(j["errors"]["series"].size(), 2u);
  const nlohmann::json& e = j["errors"]["series"][0]["error_m"];
  ASSERT_EQ(e.size(), 20u);
  for (size_t i = 0; i < e.size(); ++i) {
    EXPECT_NEAR(e[i].get<double>(), 0.01 * i, 2e-5) << i;
  }
  EXPECT_EQ(j["errors"]["series"][1]["error_m"].size(), 20u);

  // Overlays on frames 5, 10, 15 with both tracks and their tails.
  ASSERT_EQ(j["features"]["frames"].size(), 3u);
  const nlohmann::json& f = j["features"]["frames"][1];
  EXPECT_EQ(f["frame"], 10);
  EXPECT_EQ(f["width"], 160);
  ASSERT_EQ(f["tracks"].size(), 2u);
  EXPECT_EQ(f["tracks"][0].size(), 2u * 11);                 // frames 0..10
  EXPECT_DOUBLE_EQ(f["tracks"][0][20].get<double>(), 20.0);  // u at frame 10
  EXPECT_EQ(j["summary"]["tracks"], 2);
  EXPECT_EQ(j["summary"]["frames"], 20);
}

TEST_F(ReportDataTest, MissingAndCorruptFilesAreNamedAndTheRestIsKept) {
  const fs::path dir = WriteTestMap("map_bad");
  fs::remove(dir / "points.ply");
  fs::resize_file(dir / "map.glb", fs::file_size(dir / "map.glb") / 2);
  ReportInputs in;
  in.map_dir = dir;
  const ReportData r = BuildReportData(in);
  ASSERT_EQ(r.problems.size(), 2u);
  EXPECT_EQ(r.problems[0].file, (dir / "points.ply").string());
  EXPECT_EQ(r.problems[0].message, "missing");
  EXPECT_EQ(r.problems[1].file, (dir / "map.glb").string());
  EXPECT_NE(r.problems[1].message.find("truncated"), std::string::npos);
  EXPECT_EQ(r.json["problems"].size(), 2u);
  std::map<std::string, std::string> status;
  for (const auto& f : r.json["map_files"]) status[f["name"]] = f["status"];
  EXPECT_EQ(status["points.ply"], "missing");
  EXPECT_EQ(status["map.glb"], "corrupt");
  EXPECT_EQ(status["map.json"], "ok");
  // What could be read is still there: the plane and the trajectory.
  EXPECT_EQ(r.json["planes"].size(), 1u);
  EXPECT_EQ(r.json["trajectories"][0]["xyz"].size(), 60u);
  EXPECT_EQ(r.json["glb_base64"], "");
}

TEST_F(ReportDataTest, CorruptTrajectoryNamesFileAndLine) {
  const fs::path dir = WriteTestMap("map_bad_trajectory");
  const std::string text = ReadFileToString(dir / "trajectory.txt");
  const auto bad_line = std::count(text.begin(), text.end(), '\n') + 1;
  std::ofstream(dir / "trajectory.txt", std::ios::app) << "1.0 2.0 oops\n";
  ReportInputs in;
  in.map_dir = dir;
  const ReportData r = BuildReportData(in);
  ASSERT_GE(r.problems.size(), 1u);
  EXPECT_EQ(r.problems[0].file, (dir / "trajectory.txt").string());
  EXPECT_NE(r.problems[0].message.find(
                "trajectory.txt:" + std::to_string(bad_line) + ":"),
            std::string::npos)
      << r.problems[0].message;
}

TEST_F(ReportDataTest, LocalizationRunFromItsFiles) {
  const fs::path run = *root_ / "run";
  fs::create_directories(run);
  std::vector<TimedPose> estimate, truth;
  for (int i = 0; i < 5; ++i) {
    Rigid3d pose;
    pose.translation = Eigen::Vector3d(0.1 * i, 0, 0.3);
    truth.push_back({static_cast<double>(i), pose});
    pose.translation.x() += 0.02;
    estimate.push_back({static_cast<double>(i), pose});
  }
  WriteTumTrajectory(run / "trajectory.txt", estimate, "test");
  WriteTumTrajectory(run / "groundtruth.txt", truth, "test");
  WriteFileAtomic(run / "report.json",
                  R"({"steps": [{"particles": 7}, {"particles": 3}]})");
  WriteFileAtomic(run / "particles.csv",
                  "step,x,y,z,qx,qy,qz,qw,log_weight\n"
                  "0,1,2,3,0,0,0,1,-1\n0,1,2,4,0,0,0,1,-1\n"
                  "1,5,6,7,0,0,0,1,-1\n");
  std::vector<ReportProblem> problems;
  const LocalizationRunData r = ReadLocalizationRun(run.string(), &problems);
  EXPECT_TRUE(problems.empty());
  EXPECT_EQ(r.name, "run");
  EXPECT_EQ(r.trajectory.size(), 5u);
  EXPECT_EQ(r.groundtruth.size(), 5u);
  ASSERT_EQ(r.particles.size(), 2u);
  EXPECT_EQ(r.particles[0].size(), 2u);
  EXPECT_EQ(r.particles[1][0], Eigen::Vector3d(5, 6, 7));
  EXPECT_EQ(r.report["steps"][0]["particles"], 7);

  ReportInputs in;
  in.map_dir = WriteTestMap("map_for_run");
  in.localization = {r};
  const nlohmann::json j = BuildReportData(in).json["localization"][0];
  ASSERT_EQ(j["error"]["error_m"].size(), 5u);
  for (const auto& e : j["error"]["error_m"]) {
    EXPECT_NEAR(e.get<double>(), 0.02, 1e-5);
  }
  EXPECT_EQ(j["particles"]["steps"].size(), 2u);
  EXPECT_EQ(j["particles"]["xyz"][0].size(), 6u);

  // A bad particle row is named by file and line; the rest is kept.
  WriteFileAtomic(run / "particles.csv",
                  "step,x,y,z,qx,qy,qz,qw,log_weight\n0,1,2,x,0,0,0,1,-1\n");
  problems.clear();
  const LocalizationRunData bad =
      ReadLocalizationRun((run / "trajectory.txt").string() + "," +
                              (run / "particles.csv").string(),
                          &problems);
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_NE(problems[0].message.find("particles.csv:2"), std::string::npos)
      << problems[0].message;
  EXPECT_EQ(bad.trajectory.size(), 5u);
  EXPECT_TRUE(bad.particles.empty());
}

}  // namespace
}  // namespace monomap
