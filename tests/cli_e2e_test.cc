// The `monomap` binary: exit codes, error messages and atomic output.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>

#include "monomap/camera/calibration.h"
#include "monomap/geometry/polygon.h"
#include "monomap/io/colmap_export.h"
#include "monomap/io/feature_table.h"
#include "monomap/io/map_format.h"
#include "monomap/io/nav_grid_export.h"
#include "monomap/io/trajectory_io.h"
#include "monomap/localization/localizer.h"
#include "monomap/pipelines/mapping_pipeline.h"
#include "monomap/sim/simulate.h"
#include "tests/monomap_cli.h"

namespace monomap {
namespace {
namespace fs = std::filesystem;

using test::RunMonomap;
using test::RunResult;

class Cli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ =
        new fs::path(test::FolderWithDataset("monomap_cli_test", 40, 320, 240));
  }
  static void TearDownTestSuite() {
    fs::remove_all(*root_);
    delete root_;
  }
  // A copy of the good dataset to corrupt.
  static fs::path CopyData(const std::string& name) {
    const fs::path dst = *root_ / name;
    fs::remove_all(dst);
    fs::copy(*root_ / "data", dst, fs::copy_options::recursive);
    return dst;
  }
  static fs::path* root_;
};
fs::path* Cli::root_ = nullptr;

TEST_F(Cli, BuildWritesAReadableMap) {
  const fs::path out = *root_ / "map_ok";
  const RunResult r =
      RunMonomap("build " + (*root_ / "data").string() + " -o " + out.string() +
                 " -q --report " + (*root_ / "report.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Map map = ReadMap(out);
  EXPECT_EQ(map.trajectory.size(), 40u);
  EXPECT_GT(map.landmarks.size(), 50u);
  EXPECT_TRUE(fs::exists(out / "features.csv"));
  EXPECT_TRUE(fs::exists(*root_ / "report.json"));
}

// --max-image-radius leaves the rim out of the geometry, not out of the
// feature table: the report counts exactly the table's rim observations.
TEST_F(Cli, MaxImageRadiusLeavesTheRimOutOfTheGeometry) {
  const fs::path out = *root_ / "map_radius";
  const fs::path report = *root_ / "report_radius.json";
  RunResult r =
      RunMonomap("build " + (*root_ / "data").string() + " -o " + out.string() +
                 " -q --max-image-radius 100 --keep-all-points" + " --report " +
                 report.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Map map = ReadMap(out);
  EXPECT_GT(map.landmarks.size(), 50u);
  const Eigen::Vector2d centre(map.camera.cx, map.camera.cy);
  int64_t beyond = 0;
  for (const Track& t : ReadFeatureTable(out / "features.csv")) {
    for (const Observation& o : t.observations) {
      beyond += (o.px - centre).norm() > 100.0 ? 1 : 0;
    }
  }
  std::ifstream in(report);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_GT(beyond, 100);
  EXPECT_EQ(j.at("observations_beyond_radius").get<int64_t>(), beyond);
  r = RunMonomap("build " + (*root_ / "data").string() + " -o " + out.string() +
                 " -q --max-image-radius -5");
  EXPECT_EQ(r.exit_code, 2) << r.output;
}

// The export's trust filter: --keep-all-points exports every triangulated
// point, the filter leaves out exactly those failing its thresholds (counted
// per reason from the kept-all map's quality properties; the uncertainty
// test, whose covariance points.ply does not carry, off there), and the
// report says so.
TEST_F(Cli, TrustFilterLeavesOutUntrustedPointsAndKeepAllKeepsThem) {
  const std::string data = (*root_ / "data").string();
  auto build = [&](const std::string& name, const std::string& args) {
    const fs::path out = *root_ / ("map_" + name);
    const fs::path report = *root_ / ("report_" + name + ".json");
    const RunResult r = RunMonomap("build " + data + " -o " + out.string() +
                                   " -q --report " + report.string() + args);
    EXPECT_EQ(r.exit_code, 0) << r.output;
    std::ifstream in(report);
    return std::make_pair(ReadMap(out), nlohmann::json::parse(in));
  };
  const auto [all, all_report] = build("keep_all", " --keep-all-points");
  const auto [strict, strict_report] =
      build("strict",
            " --min-point-track-length 6 --min-point-angle 4"
            " --max-point-reprojection-error 0.5 --max-point-uncertainty 0");
  const auto [dflt, dflt_report] = build("trusted", "");

  const nlohmann::json& a = all_report.at("exported_points");
  EXPECT_TRUE(a.at("keep_all_points").get<bool>());
  EXPECT_EQ(a.at("exported").get<size_t>(), all.landmarks.size());
  EXPECT_EQ(a.at("points").get<size_t>(), all.landmarks.size());
  EXPECT_GT(all.landmarks.size(), 50u);

  // Recount the strict thresholds over the kept-all points (first failing
  // test claims a point, as documented). The error limit is 0.5 px or 3x
  // the points' median error, whichever is smaller: the report gives it.
  const nlohmann::json& s = strict_report.at("exported_points");
  const double limit = s.at("reprojection_limit_px").get<double>();
  EXPECT_LE(limit, 0.5);
  EXPECT_GT(limit, 0.0);
  int short_track = 0, error = 0, angle = 0;
  for (const Landmark& l : all.landmarks) {
    EXPECT_GE(l.num_observations, 3);  // the quality came through the PLY
    EXPECT_GT(l.triangulation_angle_deg, 0.0);
    if (l.num_observations < 6) {
      ++short_track;
    } else if (l.mean_reprojection_error_px > limit) {
      ++error;
    } else if (l.triangulation_angle_deg < 4.0) {
      ++angle;
    }
  }
  EXPECT_GT(short_track + error + angle, 0);
  EXPECT_FALSE(s.at("keep_all_points").get<bool>());
  EXPECT_EQ(s.at("points").get<size_t>(), all.landmarks.size());
  EXPECT_EQ(s.at("left_out").at("short_track").get<int>(), short_track);
  EXPECT_EQ(s.at("left_out").at("reprojection_error").get<int>(), error);
  EXPECT_EQ(s.at("left_out").at("triangulation_angle").get<int>(), angle);
  EXPECT_EQ(s.at("exported").get<size_t>(), strict.landmarks.size());
  EXPECT_EQ(strict.landmarks.size(),
            all.landmarks.size() - short_track - error - angle);
  for (const Landmark& l : strict.landmarks) {
    EXPECT_GE(l.num_observations, 6);
    EXPECT_LE(l.mean_reprojection_error_px, limit + 1e-6);  // stored as float
    EXPECT_GE(l.triangulation_angle_deg, 4.0 - 1e-5);
  }
  // The default build exports what the default thresholds trust.
  const nlohmann::json& d = dflt_report.at("exported_points");
  const PointTrustOptions defaults;
  EXPECT_EQ(d.at("exported").get<size_t>(), dflt.landmarks.size());
  EXPECT_EQ(d.at("exported").get<int>() +
                d.at("left_out").at("short_track").get<int>() +
                d.at("left_out").at("reprojection_error").get<int>() +
                d.at("left_out").at("triangulation_angle").get<int>() +
                d.at("left_out").at("uncertainty").get<int>(),
            d.at("points").get<int>());
  // At 320x240 some points are looser than 2 % of their depth at 1 px.
  EXPECT_GT(d.at("left_out").at("uncertainty").get<int>(), 0);
  for (const Landmark& l : dflt.landmarks) {
    EXPECT_GE(l.num_observations, defaults.min_track_length);
    EXPECT_LE(l.mean_reprojection_error_px,
              defaults.max_mean_reprojection_error_px + 1e-6);  // float
    EXPECT_GE(l.triangulation_angle_deg,
              defaults.min_triangulation_angle_deg - 1e-5);
  }
  // Bad thresholds are usage errors.
  EXPECT_EQ(
      RunMonomap("build " + data + " -o " + (*root_ / "map_bad").string() +
                 " -q --min-point-track-length 1")
          .exit_code,
      2);
}

TEST_F(Cli, MalformedOdometryLineIsNamedAndNothingIsWritten) {
  const fs::path data = CopyData("bad_odometry");
  {
    std::ofstream odo(data / "odometry.txt", std::ios::app);
    odo << "99999 1 2 3\n";
  }
  const fs::path out = *root_ / "map_bad";
  const RunResult r =
      RunMonomap("build " + data.string() + " -o " + out.string() + " -q");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("odometry.txt:"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("expected 8 values"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out));
  // No temporary directory is left behind either.
  for (const auto& e : fs::directory_iterator(*root_)) {
    EXPECT_EQ(e.path().filename().string().find(".map_bad"), std::string::npos);
  }
}

TEST_F(Cli, MissingImageAndWrongSizeAreNamed) {
  const fs::path data = CopyData("bad_image");
  fs::remove(data / "rgb" / "000003.png");
  RunResult r = RunMonomap("build " + data.string() + " -o " +
                           (*root_ / "m").string() + " -q");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("rgb.txt:"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("not found"), std::string::npos) << r.output;
}

TEST_F(Cli, UsageErrorsExitWithTwo) {
  EXPECT_EQ(RunMonomap("build").exit_code, 2);
  EXPECT_EQ(RunMonomap("no-such-command").exit_code, 2);
}

TEST_F(Cli, MissingDatasetIsNamed) {
  const RunResult r = RunMonomap("build /nonexistent/ds -o /tmp/x -q");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("/nonexistent/ds"), std::string::npos);
}

// The simulated lab corner shows no checkerboard: calibrate says so and
// writes nothing; a malformed --board and a missing --camera file are named.
TEST_F(Cli, CalibrateAndCameraOverrideErrors) {
  const fs::path data = *root_ / "data";
  const fs::path out = *root_ / "calibrated.yaml";
  RunResult r = RunMonomap("calibrate " + data.string() + " -o " +
                           out.string() + " --stride 4");
  EXPECT_EQ(r.exit_code, 3) << r.output;  // a stage that cannot do its job
  EXPECT_NE(r.output.find("board was found in 0 of 10 frames"),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(out));
  // --first-frame / --frames restrict the views (for a held-out check).
  r = RunMonomap("calibrate " + data.string() + " -o " + out.string() +
                 " --first-frame 6 --frames 3 --stride 1");
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("board was found in 0 of 3 frames"),
            std::string::npos)
      << r.output;
  r = RunMonomap("eval board-poses " + data.string() + " --structure " +
                 (data / "groundtruth_structure.yaml").string() + " -o " +
                 out.string() + " --first-frame 100000");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("first_frame 100000"), std::string::npos) << r.output;
  r = RunMonomap("calibrate " + data.string() + " -o " + out.string() +
                 " --board 9y6");
  EXPECT_EQ(r.exit_code, 2) << r.output;  // a usage error
  EXPECT_NE(r.output.find("--board"), std::string::npos) << r.output;
  r = RunMonomap("build " + data.string() + " -o " +
                 (*root_ / "m_cam").string() +
                 " -q --camera /nonexistent/camera.yaml");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("/nonexistent/camera.yaml"), std::string::npos)
      << r.output;
  // The dataset's own calibration given explicitly builds the same map.
  r = RunMonomap("build " + data.string() + " -o " +
                 (*root_ / "m_cam").string() + " -q --camera " +
                 (data / "camera.yaml").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_GT(ReadMap(*root_ / "m_cam").landmarks.size(), 50u);
}

// `eval points --over-board` keeps the points over the YAML's chessboard
// (issue 18's protocol on the desk), `--align` moves the map into the
// ground truth's frame first; misused flags are usage errors.
TEST_F(Cli, EvalPointsOverTheBoardAndAligned) {
  const fs::path data = *root_ / "data";
  const fs::path map = *root_ / "map_points";
  RunResult r =
      RunMonomap("build " + data.string() + " -o " + map.string() + " -q");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // A 4 x 3 board of 25 cm squares on the floor z = 0, centred under the
  // points' median.
  const Map m = ReadMap(map);
  std::vector<double> xs, ys;
  for (const Landmark& l : m.landmarks) {
    xs.push_back(l.x_in_world.x());
    ys.push_back(l.x_in_world.y());
  }
  std::nth_element(xs.begin(), xs.begin() + xs.size() / 2, xs.end());
  std::nth_element(ys.begin(), ys.begin() + ys.size() / 2, ys.end());
  const fs::path yaml = *root_ / "board.yaml";
  std::ofstream(yaml) << "plane: {normal: [0, 0, 1], offset: 0.0}\n"
                      << "chessboard: {inner_corners_x: 3, inner_corners_y: 2, "
                      << "square_m: 0.25, origin: [" << xs[xs.size() / 2] - 0.375
                      << ", " << ys[ys.size() / 2] - 0.25
                      << ", 0], x_axis: [1, 0, 0], y_axis: [0, 1, 0]}\n";
  auto evaluate = [&](const std::string& flags) {
    const fs::path json = *root_ / "points.json";
    const RunResult run = RunMonomap("eval points " + map.string() +
                                     " --plane " + yaml.string() + " " + flags +
                                     " --json " + json.string());
    EXPECT_EQ(run.exit_code, 0) << run.output;
    std::ifstream in(json);
    const nlohmann::json j = nlohmann::json::parse(in);
    return j;
  };
  const nlohmann::json all = evaluate("");
  const nlohmann::json board = evaluate("--over-board");
  const size_t n_all = all.at("absolute_m").at("count").get<size_t>();
  const size_t n_board = board.at("absolute_m").at("count").get<size_t>();
  EXPECT_GT(n_board, 10u);
  EXPECT_LT(n_board, n_all / 2);
  EXPECT_TRUE(board.at("over_board").get<bool>());
  const nlohmann::json aligned = evaluate(
      "--over-board --align sim3-poses --groundtruth " +
      (data / "groundtruth.txt").string());
  EXPECT_EQ(aligned.at("alignment").get<std::string>(), "sim3-poses");
  EXPECT_GT(aligned.at("absolute_m").at("count").get<size_t>(), 10u);
  // Misuse: --over-board without --plane, --align without --groundtruth.
  r = RunMonomap("eval points " + map.string() + " --surface " +
                 yaml.string() + " --over-board");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--over-board needs --plane"), std::string::npos);
  r = RunMonomap("eval points " + map.string() + " --plane " + yaml.string() +
                 " --align se3");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--groundtruth"), std::string::npos) << r.output;
  // eval checkerboard takes the same pair, checked before it reads the
  // structure.
  r = RunMonomap("eval checkerboard " + map.string() + " --structure " +
                 yaml.string() + " --align sim3-poses");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("eval checkerboard: --align sim3-poses needs "
                          "--groundtruth"),
            std::string::npos)
      << r.output;
}

TEST_F(Cli, EvalStructurePrintsTheTableAndWritesJson) {
  const fs::path data = *root_ / "data";
  const fs::path map = *root_ / "map_structure";
  RunResult r =
      RunMonomap("build " + data.string() + " -o " + map.string() + " -q");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const fs::path json = *root_ / "structure.json";
  r = RunMonomap("eval structure " + map.string() + " --structure " +
                 (data / "structure").string() + " --json " + json.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("structure accuracy (alignment none)"),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("plane precision"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("on planes rel (%)"), std::string::npos) << r.output;
  std::ifstream in(json);
  const std::string text((std::istreambuf_iterator<char>(in)),
                         std::istreambuf_iterator<char>());
  for (const char* key :
       {"\"counts\"", "\"point_error\"", "\"planes\"", "\"true_planes\"",
        "\"precision\"", "\"recall\"", "\"alignment\": \"none\""}) {
    EXPECT_NE(text.find(key), std::string::npos) << key << "\n" << text;
  }
  // Relative errors use the depths from features.csv, not 0.
  EXPECT_NE(text.find("mean_distance_to_observing_cameras"), std::string::npos);

  r = RunMonomap("eval structure " + map.string() + " --structure " +
                 (data / "structure").string() +
                 " --align first-pose --groundtruth " +
                 (data / "groundtruth.txt").string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("(alignment first-pose)"), std::string::npos)
      << r.output;
  // The similarity fit of the trajectory: the scale the odometry gave the
  // map (the simulator's wheel-radius error is 1 %), removed.
  const fs::path sim3_json = *root_ / "structure_sim3.json";
  r = RunMonomap(
      "eval structure " + map.string() + " --structure " +
      (data / "structure").string() + " --align sim3 --groundtruth " +
      (data / "groundtruth.txt").string() + " --json " + sim3_json.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream sim3_in(sim3_json);
  const nlohmann::json j = nlohmann::json::parse(sim3_in);
  EXPECT_EQ(j["alignment"], "sim3");
  EXPECT_NEAR(j["alignment_scale"].get<double>(), 1.0, 0.05);
  EXPECT_NE(j["alignment_scale"].get<double>(), 1.0);
}

// The export moves plane inliers to their plane's local offset, which
// brings the exported points (all of them, outliers included) closer to
// the true surfaces than where triangulation put them; --raw-points keeps
// the triangulated positions. Scored after the similarity that fits the
// map's trajectory to the truth (the odometry's 1 % scale error removed).
TEST_F(Cli, InlierRefinementBringsTheExportedPointsCloserToTheSurfaces) {
  const fs::path data = *root_ / "data";
  double median[2];
  size_t count[2];
  for (int raw = 0; raw < 2; ++raw) {
    const std::string tag = raw ? "raw" : "refined";
    const fs::path map = *root_ / ("map_" + tag);
    const fs::path report = *root_ / ("report_" + tag + ".json");
    RunResult r = RunMonomap("build " + data.string() + " -o " + map.string() +
                             " -q --report " + report.string() +
                             (raw ? " --raw-points" : ""));
    ASSERT_EQ(r.exit_code, 0) << r.output;
    std::ifstream report_in(report);
    const nlohmann::json refinement =
        nlohmann::json::parse(report_in).at("inlier_refinement");
    const Map built = ReadMap(map);
    const auto inliers = std::count_if(
        built.landmarks.begin(), built.landmarks.end(),
        [](const Landmark& l) { return l.plane_id >= 0; });
    EXPECT_GT(inliers, 50);
    EXPECT_EQ(refinement.at("enabled").get<bool>(), raw == 0);
    EXPECT_EQ(refinement.at("moved").get<int>(), raw ? 0 : inliers);
    const fs::path json = *root_ / ("eval_" + tag + ".json");
    r = RunMonomap("eval structure " + map.string() + " --structure " +
                   (data / "structure").string() +
                   " --align sim3-poses --groundtruth " +
                   (data / "groundtruth.txt").string() + " --json " +
                   json.string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    std::ifstream eval_in(json);
    const nlohmann::json all = nlohmann::json::parse(eval_in)
                                   .at("point_error")
                                   .at("all_landmarks")
                                   .at("relative_percent");
    median[raw] = all.at("median").get<double>();
    count[raw] = all.at("count").get<size_t>();
  }
  std::printf("median error of all points: raw %.3f %%, refined %.3f %%\n",
              median[1], median[0]);
  // Measured (40 frames, 320x240): 0.105 -> 0.071 %.
  EXPECT_EQ(count[0], count[1]);
  EXPECT_LT(median[0], 0.8 * median[1]);
}

// build --debug-growth DIR: an image and the verdict counts
// per plane; a grown plane's grown cells carry the verdicts they joined on
// (textured: as many as the build report counts; for a plane without
// hypothesis cells).
TEST_F(Cli, DebugGrowthWritesEachPlanesCellVerdicts) {
  const fs::path data = *root_ / "data";
  const fs::path map = *root_ / "map_debug_growth";
  const fs::path dir = *root_ / "growth_cells";
  const fs::path report = *root_ / "debug_growth_report.json";
  RunResult r = RunMonomap("build " + data.string() + " -o " + map.string() +
                           " -q --debug-growth " + dir.string() + " --report " +
                           report.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream cells_in(dir / "cells.json");
  const nlohmann::json cells = nlohmann::json::parse(cells_in);
  std::ifstream report_in(report);
  const nlohmann::json growth =
      nlohmann::json::parse(report_in)["plane_growth"];
  ASSERT_FALSE(cells["planes"].empty());
  int grown = 0;
  for (const auto& p : cells["planes"]) {
    const cv::Mat image =
        cv::imread((dir / p["image"].get<std::string>()).string());
    ASSERT_FALSE(image.empty()) << p["image"];
    EXPECT_EQ(image.rows, 4 * p["rows"].get<int>());
    EXPECT_EQ(image.cols, 4 * p["cols"].get<int>());
    int all = 0;
    for (const auto& [verdict, n] : p["cells"].items()) all += n.get<int>();
    EXPECT_EQ(all, p["rows"].get<int>() * p["cols"].get<int>());
    bool hypothesis = false;  // its count includes the hull's cells
    for (const auto& h : growth["hypotheses"]) {
      hypothesis = hypothesis || h["plane_id"] == p["plane_id"];
    }
    for (const auto& g : growth["planes"]) {
      if (g["plane_id"] != p["plane_id"] || hypothesis) continue;
      EXPECT_EQ(p["grown_cells"]["textured"].get<int>(),
                g["cells_textured"].get<int>());
    }
    grown += p["grown_cells"]["textured"].get<int>() +
             p["grown_cells"]["plain"].get<int>();
  }
  EXPECT_GT(grown, 0);
  // Without growth there is nothing to show: refused before any work.
  r = RunMonomap(
      "build " + data.string() + " -o " + (*root_ / "map_x").string() +
      " -q --no-grow-planes --debug-growth " + (*root_ / "cells_x").string());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("--debug-growth"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(*root_ / "map_x"));
}

// build (growth is the default) against build --no-grow-planes: the planes
// grow beyond their points over what the images explain, and plane
// hypotheses (--plane-hypotheses) are checked; the report says by how much,
// more of the world's seen structure is recovered while the grown area
// stays on it, and the map keeps what the points support for localization.
TEST_F(Cli, GrowPlanesRecoversMoreOfTheSeenStructure) {
  const fs::path data = *root_ / "data";
  double recall[2], precision[2];
  for (int grow = 0; grow < 2; ++grow) {
    const fs::path map = *root_ / ("map_grow" + std::to_string(grow));
    const fs::path report = *root_ / ("grow_report" + std::to_string(grow) + ".json");
    RunResult r = RunMonomap(
        "build " + data.string() + " -o " + map.string() + " -q --report " +
        report.string() + (grow ? " --plane-hypotheses" : " --no-grow-planes"));
    ASSERT_EQ(r.exit_code, 0) << r.output;
    std::ifstream report_in(report);
    const nlohmann::json build_report = nlohmann::json::parse(report_in);
    const nlohmann::json& growth = build_report["plane_growth"];
    EXPECT_EQ(growth["planes"].size(), grow ? ReadMap(map).planes.size() : 0u);
    // Plane hypotheses are checked only with growth; a confirmed one is a
    // map plane.
    ASSERT_TRUE(growth["hypotheses"].is_array());
    if (!grow) {
      EXPECT_TRUE(growth["hypotheses"].empty());
    }
    for (const auto& h : growth["hypotheses"]) {
      EXPECT_GE(h["inliers"].get<int>(), 5);
      EXPECT_EQ(h["confirmed"].get<bool>(), h["plane_id"].get<int>() >= 0);
      EXPECT_LT(h["plane_id"].get<int>(),
                static_cast<int>(ReadMap(map).planes.size()));
    }
    // The planes block counts the map's segments, the confirmed hypotheses'
    // among them: every point is an inlier of one, or an outlier.
    const nlohmann::json& planes = build_report["planes"];
    int confirmed = 0;
    for (const auto& h : growth["hypotheses"]) confirmed += h["confirmed"].get<bool>();
    EXPECT_EQ(planes["from_hypotheses"].get<int>(), confirmed);
    ASSERT_EQ(planes["inliers_per_plane"].size(), planes["planes"].get<size_t>());
    int inliers = 0;
    for (const auto& n : planes["inliers_per_plane"]) inliers += n.get<int>();
    EXPECT_EQ(inliers + planes["outliers"].get<int>(),
              build_report["exported_points"]["points"].get<int>());
    for (const auto& p : growth["planes"]) {
      EXPECT_GE(p["area_after_m2"].get<double>(),
                p["area_before_m2"].get<double>());
    }
    // A plane reaching past its inliers (over absorbed loose points, or
    // grown) keeps their extent, inside the larger one.
    int with_landmark_polygon = 0;
    for (const TexturedPlane& p : ReadMap(map).planes) {
      if (p.landmark_polygon.empty()) continue;
      ++with_landmark_polygon;
      EXPECT_LT(std::abs(PolygonArea(p.landmark_polygon)),
                std::abs(PolygonArea(p.polygon)));
    }
    if (grow) {
      EXPECT_GE(with_landmark_polygon, 1);
    }
    const fs::path json = *root_ / ("grow_eval" + std::to_string(grow) + ".json");
    r = RunMonomap("eval structure " + map.string() + " --structure " +
                   (data / "structure").string() + " --json " + json.string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    std::ifstream eval_in(json);
    const nlohmann::json area = nlohmann::json::parse(eval_in)["area"];
    recall[grow] = area["area_recall"].get<double>();
    precision[grow] = area["area_precision"].get<double>();
  }
  std::printf("area recovered %.3f -> %.3f, on the truth %.3f -> %.3f\n",
              recall[0], recall[1], precision[0], precision[1]);
  // Measured (40 frames, 320x240): 0.162 -> 0.192, all of it on the truth.
  EXPECT_GT(recall[1], recall[0] + 0.015);
  EXPECT_GT(precision[1], 0.95);
}

TEST_F(Cli, EvalStructureErrorsNameThePath) {
  const fs::path data = *root_ / "data";
  // A missing map or structure directory: exit 1, the path named.
  RunResult r = RunMonomap("eval structure /nonexistent/map --structure " +
                           (data / "structure").string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("/nonexistent/map"), std::string::npos) << r.output;
  r = RunMonomap("eval structure " + (data / "structure").string() +
                 " --structure /nonexistent/structure");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("/nonexistent/structure"), std::string::npos)
      << r.output;
  // Usage errors exit with 2.
  r = RunMonomap("eval structure " + (data / "structure").string() +
                 " --structure " + (data / "structure").string() +
                 " --align first-pose");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--groundtruth"), std::string::npos) << r.output;
  EXPECT_EQ(RunMonomap("eval structure " + (data / "structure").string() +
                       " --structure " + (data / "structure").string() +
                       " --align sim3")
                .exit_code,
            2);
  EXPECT_EQ(
      RunMonomap("eval structure " + (data / "structure").string()).exit_code,
      2);
}

// Distance from p to the nearest edge of the polygon (inside or out).
double DistanceToOutline(const Polygon2d& polygon, const Eigen::Vector2d& p) {
  double best = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < polygon.size(); ++i) {
    const Eigen::Vector2d& a = polygon[i];
    const Eigen::Vector2d& b = polygon[(i + 1) % polygon.size()];
    const Eigen::Vector2d ab = b - a;
    const double s = std::clamp(
        (p - a).dot(ab) / std::max(ab.squaredNorm(), 1e-300), 0.0, 1.0);
    best = std::min(best, (a + s * ab - p).norm());
  }
  return best;
}

// `render` through the binary: the simulated world's true planes (its
// structure/ map) from a true pose given in TUM order, at a scaled size.
// The depth image must be the ray-plane intersection of the nearest plane;
// bad output names are refused before anything is written.
TEST_F(Cli, RenderWritesTheViewAndItsDepth) {
  const fs::path structure = *root_ / "data" / "structure";
  const std::vector<TimedPose> truth =
      ReadTumTrajectory(*root_ / "data" / "groundtruth.txt");
  const Rigid3d& world_from_cam = truth[20].world_from_cam;
  const Eigen::Quaterniond& q = world_from_cam.rotation;
  const Eigen::Vector3d& t = world_from_cam.translation;
  char pose[256];
  std::snprintf(pose, sizeof(pose), "%.9f %.9f %.9f %.9f %.9f %.9f %.9f", t.x(),
                t.y(), t.z(), q.x(), q.y(), q.z(), q.w());
  const fs::path view = *root_ / "view.png", depth = *root_ / "depth.tiff";
  const std::string args = "render " + structure.string() + " --pose \"" +
                           pose + "\" --size 160x120";
  RunResult r =
      RunMonomap(args + " -o " + view.string() + " --depth " + depth.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const cv::Mat grey = cv::imread(view.string(), cv::IMREAD_UNCHANGED);
  const cv::Mat z = cv::imread(depth.string(), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(grey.type(), CV_8UC1);
  ASSERT_EQ(z.type(), CV_32FC1);
  ASSERT_EQ(grey.size(), cv::Size(160, 120));
  ASSERT_EQ(z.size(), cv::Size(160, 120));

  const Map map = ReadMap(structure);
  const Camera cam = map.camera.Pinhole().Scaled(160, 120);
  int hit = 0, agree = 0, background = 0, near_edge = 0;
  for (int v = 0; v < cam.height; ++v) {
    for (int u = 0; u < cam.width; ++u) {
      const Eigen::Vector3d ray_in_cam((u - cam.cx) / cam.fx,
                                       (v - cam.cy) / cam.fy, 1.0);
      const Eigen::Vector3d ray = world_from_cam.rotation * ray_in_cam;
      double nearest = 0.0;  // depth along the optical axis
      bool edge = false;
      for (const TexturedPlane& p : map.planes) {
        const double denom = p.plane.normal.dot(ray);
        if (std::abs(denom) < 1e-12) continue;
        const double lambda = -p.plane.SignedDistance(t) / denom;
        if (lambda <= 0.0) continue;
        const Eigen::Vector2d st = p.frame.ToPlane(t + lambda * ray);
        // Pixels whose ray passes within 2 cm of an outline are skipped:
        // there a pixel's centre and its coverage may disagree.
        const bool inside = PointInPolygon(p.polygon, st);
        if (DistanceToOutline(p.polygon, st) < 0.02) edge = true;
        if (inside && (nearest == 0.0 || lambda < nearest)) nearest = lambda;
      }
      const float rendered = z.at<float>(v, u);
      if (edge) {
        ++near_edge;
      } else if (nearest == 0.0) {
        background += rendered == 0.0f;
      } else {
        ++hit;
        agree += std::abs(rendered - nearest) < 1e-4 * nearest;
      }
    }
  }
  std::printf(
      "render: %d px on a plane (%d agree), %d background, %d near "
      "an outline\n",
      hit, agree, background, near_edge);
  EXPECT_GT(hit, 160 * 120 / 2);
  EXPECT_EQ(agree, hit);
  EXPECT_EQ(hit + background + near_edge, 160 * 120);

  // Refused before rendering (usage errors), nothing written: an image
  // format OpenCV does not know, and 32-bit depth in a format that would
  // round it to 8 bits.
  const fs::path view2 = *root_ / "view2.png", bad = *root_ / "view.xyz";
  r = RunMonomap(args + " -o " + bad.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("view.xyz"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(bad));
  r = RunMonomap(args + " -o " + view2.string() + " --depth " +
                 (*root_ / "depth.png").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("depth.png"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(view2));
  EXPECT_FALSE(fs::exists(*root_ / "depth.png"));
  // An output folder that does not exist is named; exit 3 (output error).
  r = RunMonomap(args + " -o " + (*root_ / "no_dir" / "v.png").string());
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("no_dir/v.png: cannot open"), std::string::npos)
      << r.output;
}

// Texture fidelity on held-out frames: a map of the first 30 frames
// rendered from the true poses of the last 10 matches their images.
TEST_F(Cli, EvalRenderComparesHeldOutFrames) {
  const fs::path data = *root_ / "data";
  const fs::path map = *root_ / "map_render";
  RunResult r = RunMonomap("build " + data.string() + " --frames 30 -o " +
                           map.string() + " -q");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const fs::path json = *root_ / "render.json";
  r = RunMonomap("eval render " + map.string() + " " + data.string() +
                 " --first-frame 30 --stride 2 --json " + json.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("texture fidelity (alignment none)"),
            std::string::npos)
      << r.output;
  std::ifstream in(json);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["compared"].get<int>() + j["skipped"].get<int>(), 5);
  EXPECT_GE(j["compared"].get<int>(), 3);
  EXPECT_GT(j["ncc"]["median"].get<double>(), 0.8);
  EXPECT_GT(j["psnr_db"]["median"].get<double>(), 18.0);
  EXPECT_EQ(j["frames"][0]["frame"].get<int>(), 30);
  // From poses 5 cm off (the default --wrong-offset) the images match
  // clearly worse, in every frame (measured: NCC median 0.64 against 0.95).
  const nlohmann::json& wrong = j["wrong_pose"];
  EXPECT_DOUBLE_EQ(wrong["offset_m"].get<double>(), 0.05);
  EXPECT_GE(wrong["compared"].get<int>(), 3);
  EXPECT_DOUBLE_EQ(wrong["true_pose_better"].get<double>(), 1.0);
  EXPECT_LT(wrong["ncc"]["median"].get<double>(),
            j["ncc"]["median"].get<double>() - 0.1)
      << wrong.dump();

  // No ground truth: the dataset is named, exit 1.
  const fs::path blind = CopyData("data_no_gt");
  fs::remove(blind / "groundtruth.txt");
  r = RunMonomap("eval render " + map.string() + " " + blind.string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("groundtruth.txt"), std::string::npos) << r.output;
  EXPECT_EQ(RunMonomap("eval render " + map.string() + " " + data.string() +
                       " --stride 0")
                .exit_code,
            2);
}

// Localization end to end through the binary: a map of the 40 frames,
// the same frames localized from their first odometry pose (planar MCC;
// the simulated odometry starts at the true pose), the
// trajectory, report and particle sets written, errors in centimetres.
TEST_F(Cli, LocalizeTracksTheDatasetInItsMap) {
  const fs::path data = *root_ / "data";
  const fs::path map = *root_ / "map_localize";
  RunResult r =
      RunMonomap("build " + data.string() + " -o " + map.string() + " -q");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const fs::path traj = *root_ / "localized.txt";
  const fs::path report = *root_ / "localize.json";
  const fs::path particles = *root_ / "particles.csv";
  r = RunMonomap("localize " + map.string() + " " + data.string() +
                 " --method mcc --init pose --particles 200 -o " +
                 traj.string() + " --report " + report.string() +
                 " --particles-out " + particles.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream in(report);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["frames"].get<int>(), 40);
  // Measured 5 mm rms, 8 mm at the end.
  EXPECT_LT(j["rmse_translation_m"].get<double>(), 0.02);
  EXPECT_LT(j["final_translation_error_m"].get<double>(), 0.03);
  // The budget caps KLD-sampling: never more than 200 particles.
  for (const auto& step : j["steps"]) {
    EXPECT_LE(step["particles"].get<int>(), 200);
  }
  r = RunMonomap("eval trajectory " + traj.string() + " " +
                 (data / "groundtruth.txt").string() + " --align none");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("matched 40"), std::string::npos) << r.output;
  // The particle sets: one row per particle and step, the columns named in
  // the header, unit quaternions, every step of the report present.
  std::ifstream sets_in(particles);
  std::string header;
  std::getline(sets_in, header);
  EXPECT_EQ(header, "step,x,y,z,qx,qy,qz,qw,log_weight");
  size_t rows = 0;
  int last_step = -1;
  for (std::string row; std::getline(sets_in, row); ++rows) {
    std::replace(row.begin(), row.end(), ',', ' ');
    std::istringstream f(row);
    int step;
    double x, y, z, qx, qy, qz, qw, lw;
    ASSERT_TRUE(f >> step >> x >> y >> z >> qx >> qy >> qz >> qw >> lw) << row;
    EXPECT_NEAR(qx * qx + qy * qy + qz * qz + qw * qw, 1.0, 1e-5) << row;
    last_step = std::max(last_step, step);
  }
  size_t particles_total = 0;
  for (const auto& step : j["steps"]) {
    particles_total += step["particles"].get<size_t>();
  }
  EXPECT_EQ(rows, particles_total);
  EXPECT_EQ(last_step, 39);

  // Self-localization: the frames the map was built from, localized in it,
  // give back the map's own poses if its textures agree with them (a
  // texture registered to anything else shows here). Measured 1.0 mm /
  // 0.023 deg median.
  const fs::path self_json = *root_ / "self.json";
  r = RunMonomap("eval trajectory " + traj.string() + " " +
                 (map / "trajectory.txt").string() + " --align none --json " +
                 self_json.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream self_in(self_json);
  const nlohmann::json self = nlohmann::json::parse(self_in);
  EXPECT_EQ(self["ate"]["matched"].get<int>(), 40);
  EXPECT_LT(self["ate"]["translation_m"]["median"].get<double>(), 0.003);
  EXPECT_LT(self["ate"]["rotation_deg"]["median"].get<double>(), 0.1);

  // A missing map is named (exit 1); a budget below 10 is a usage error.
  r = RunMonomap("localize /nonexistent/map " + data.string() + " -o " +
                 (*root_ / "x.txt").string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("/nonexistent/map"), std::string::npos) << r.output;
  EXPECT_EQ(RunMonomap("localize " + map.string() + " " + data.string() +
                       " --particles 5 -o " + (*root_ / "x.txt").string())
                .exit_code,
            2);
  EXPECT_FALSE(fs::exists(*root_ / "x.txt"));
  // An explicit start pose: the first ground-truth line, moved 0.3 m.
  // Started there, MCL is off by about that much after one update (the run
  // above started at the first odometry pose, here the true one).
  std::ifstream gt_in(data / "groundtruth.txt");
  std::string line;
  while (std::getline(gt_in, line) && (line.empty() || line[0] == '#')) {
  }
  std::istringstream fields(line);
  double stamp, tx, ty, tz, qx, qy, qz, qw;
  ASSERT_TRUE(fields >> stamp >> tx >> ty >> tz >> qx >> qy >> qz >> qw);
  char pose[200];
  std::snprintf(pose, sizeof(pose), "%.6f %.6f %.6f %.9f %.9f %.9f %.9f",
                tx + 0.3, ty, tz, qx, qy, qz, qw);
  const fs::path moved = *root_ / "moved.json";
  r = RunMonomap("localize " + map.string() + " " + data.string() +
                 " --method mcl --frames 1 --particles 100 --init-pose \"" +
                 pose + "\" -o " + (*root_ / "moved.txt").string() +
                 " --report " + moved.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream moved_in(moved);
  const nlohmann::json mj = nlohmann::json::parse(moved_in);
  EXPECT_GT(mj["final_translation_error_m"].get<double>(), 0.15);
  // A refinement narrower than 16 px is refused.
  r = RunMonomap("localize " + map.string() + " " + data.string() +
                 " --refine-width 8 -o " + (*root_ / "x.txt").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--refine-width"), std::string::npos) << r.output;
  // --init-pose is for --init pose only; a malformed pose is named.
  r = RunMonomap("localize " + map.string() + " " + data.string() +
                 " --init global --init-pose \"" + pose + "\" -o " +
                 (*root_ / "x.txt").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--init-pose"), std::string::npos) << r.output;
  r = RunMonomap("localize " + map.string() + " " + data.string() +
                 " --init-pose \"1 2 3\" -o " + (*root_ / "x.txt").string());
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("--init-pose"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(*root_ / "x.txt"));

  // The planar state without 2D odometry names the file it needs.
  const fs::path no2d = CopyData("data_no_odometry2d");
  fs::remove(no2d / "odometry2d.txt");
  r = RunMonomap("localize " + map.string() + " " + no2d.string() + " -o " +
                 (*root_ / "x.txt").string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("odometry2d.txt"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(*root_ / "x.txt"));
}

// `export` on a built map: a COLMAP model named after the dataset's images
// (read back by our reader, and by COLMAP when installed), a navigation
// grid and a glb with extras; a bad height band writes nothing; --version
// and an unknown subcommand.
TEST_F(Cli, ExportWritesColmapNavGridAndGlb) {
  const fs::path data = *root_ / "data";
  const fs::path map_dir = *root_ / "map_export";
  RunResult r =
      RunMonomap("build " + data.string() + " -o " + map_dir.string() + " -q");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const fs::path out = *root_ / "export";
  r = RunMonomap("export " + map_dir.string() + " --colmap " +
                 (out / "colmap").string() + " --images " + data.string() +
                 " --nav-grid " + (out / "nav").string() +
                 " --resolution 0.1 --glb " + (out / "map.glb").string() +
                 " --camera-path --points --y-up");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::printf("%s", r.output.c_str());
  const Map map = ReadMap(map_dir);
  const ColmapModel model = ReadColmapText(out / "colmap");
  ASSERT_EQ(model.images.size(), map.trajectory.size());
  ASSERT_EQ(model.points.size(), map.landmarks.size());
  for (const auto& im : model.images) {
    EXPECT_TRUE(fs::exists(data / im.name)) << im.name;
  }
  // Every landmark of a built map is triangulated from its track; the
  // ERROR field is its reprojection error in the refined map.
  double error_sum = 0;
  size_t observations = 0;
  for (const auto& p : model.points) {
    EXPECT_GE(p.track.size(), 2u) << "point " << p.id;
    error_sum += p.error * p.track.size();
    observations += p.track.size();
  }
  const double mean_error_px = error_sum / observations;
  std::printf(
      "COLMAP export of the built map: mean reprojection error "
      "%.3f px over %zu observations\n",
      mean_error_px, observations);
  EXPECT_LT(mean_error_px, 1.0);
  if (std::system("command -v colmap > /dev/null 2>&1") == 0) {
    const std::string cmd = "colmap model_analyzer --path " +
                            (out / "colmap").string() + " > " +
                            (out / "analyzer.log").string() + " 2>&1";
    EXPECT_EQ(std::system(cmd.c_str()), 0);
    std::ifstream log(out / "analyzer.log");
    const std::string text((std::istreambuf_iterator<char>(log)), {});
    EXPECT_NE(text.find("Points: " + std::to_string(model.points.size())),
              std::string::npos)
        << text;
  }
  const NavGrid grid = ReadNavGrid(out / "nav" / "map.yaml");
  EXPECT_DOUBLE_EQ(grid.resolution_m, 0.1);
  EXPECT_GT(cv::countNonZero(grid.cells == uint8_t(NavCell::kFree)), 100);
  EXPECT_GT(fs::file_size(out / "map.glb"), 1000u);

  r = RunMonomap("export " + map_dir.string() + " --nav-grid " +
                 (out / "bad").string() + " --z-band 2 1");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("min_z_m"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out / "bad"));
  r = RunMonomap("exprot " + map_dir.string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("unknown subcommand 'exprot'"), std::string::npos)
      << r.output;
  r = RunMonomap("--version");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_EQ(r.output.rfind("monomap 0.", 0), 0u) << r.output;
  EXPECT_NE(r.output.find("commit "), std::string::npos) << r.output;
}

// The default `help` shows for `option` (CLI11 prints "--name TYPE=VALUE"),
// "" if none.
std::string HelpDefault(const std::string& help, const std::string& option) {
  std::istringstream in(help);
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream words(line);
    std::string name, type;
    words >> name >> type;
    if (name != option) continue;
    const size_t eq = type.rfind('=');
    return eq == std::string::npos ? "" : type.substr(eq + 1);
  }
  return "";
}

// CLI11 prints a default as the value streamed into a string.
template <typename T>
std::string Shown(const T& value) {
  std::ostringstream s;
  s << value;
  return s.str();
}

// --help shows the defaults of the library's option structs, not copies.
TEST(CliHelp, BuildShowsTheMappingOptionsDefaults) {
  const RunResult r = RunMonomap("build --help");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const MappingOptions o;
  EXPECT_EQ(HelpDefault(r.output, "--ransac-iterations"),
            Shown(o.planes.ransac_iterations))
      << r.output;
  EXPECT_EQ(HelpDefault(r.output, "--keyframe-interval"),
            Shown(o.keyframes.interval));
  EXPECT_EQ(HelpDefault(r.output, "--features"),
            Shown(o.tracking.target_features));
  EXPECT_EQ(HelpDefault(r.output, "--odometry-translation-sigma"),
            Shown(o.bundle_adjustment.translation_sigma_fraction));
  EXPECT_EQ(HelpDefault(r.output, "--odometry-span-rotation-sigma-deg"),
            Shown(o.bundle_adjustment.span_rotation_sigma_deg));
  EXPECT_EQ(HelpDefault(r.output, "--ba-loss"), o.bundle_adjustment.loss);
  EXPECT_EQ(HelpDefault(r.output, "--ba-loss-scale"),
            Shown(o.bundle_adjustment.loss_scale_px));
  // A loss the adjustment does not know is a usage error (exit 2).
  const RunResult bad = RunMonomap("build . -o out --ba-loss tukey");
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_NE(bad.output.find("--ba-loss"), std::string::npos) << bad.output;
}

TEST(CliHelp, LocalizeShowsTheLocalizerOptionsDefaults) {
  const RunResult r = RunMonomap("localize --help");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const LocalizerOptions o;
  EXPECT_EQ(HelpDefault(r.output, "--mcc-top-k"), Shown(o.mcc.top_k))
      << r.output;
  EXPECT_EQ(HelpDefault(r.output, "--relocalize-ncc-drop"),
            Shown(o.recovery.relocalize_ncc_drop));
  EXPECT_EQ(HelpDefault(r.output, "--seed"), Shown(o.seed));
  EXPECT_EQ(HelpDefault(r.output, "--mcc-size"),
            Shown(o.mcc.corrector.width) + "x" + Shown(o.mcc.corrector.height));
  EXPECT_EQ(
      HelpDefault(r.output, "--measure-size"),
      Shown(o.mcl.measurement.width) + "x" + Shown(o.mcl.measurement.height));
}

TEST(CliHelp, SimulateAndCalibrateShowTheirOptionsDefaults) {
  const RunResult sim = RunMonomap("simulate --help");
  ASSERT_EQ(sim.exit_code, 0) << sim.output;
  const SimulationOptions s;
  EXPECT_EQ(HelpDefault(sim.output, "--width"), Shown(s.width)) << sim.output;
  EXPECT_EQ(HelpDefault(sim.output, "--speed"), Shown(s.path.speed_mps));
  EXPECT_EQ(HelpDefault(sim.output, "--fps"), Shown(s.path.rate_hz));
  EXPECT_EQ(HelpDefault(sim.output, "--camera-height"),
            Shown(s.mount.height_m));
  EXPECT_EQ(HelpDefault(sim.output, "--camera-tilt"),
            Shown(s.mount.tilt_down_deg));
  EXPECT_EQ(HelpDefault(sim.output, "--k1"), Shown(s.k1));
  const RunResult cal = RunMonomap("calibrate --help");
  ASSERT_EQ(cal.exit_code, 0) << cal.output;
  const CalibrationOptions c;
  EXPECT_EQ(HelpDefault(cal.output, "--board"),
            std::to_string(c.inner_corners_x) + "x" +
                std::to_string(c.inner_corners_y))
      << cal.output;
  EXPECT_EQ(HelpDefault(cal.output, "--square"), Shown(c.square_m));
}

}  // namespace
}  // namespace monomap
