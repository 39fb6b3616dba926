// The report from the command line: `build --html`, `localize --html` and
// `monomap report` on a simulated dataset, and a map directory with a
// missing and a corrupt file (named, exit status 1, page still written).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "monomap/sim/simulate.h"
#include "monomap/util/file.h"
#include "tests/monomap_cli.h"

namespace monomap {
namespace {
namespace fs = std::filesystem;
using test::RunMonomap;
using test::RunResult;

nlohmann::json ReadJson(const fs::path& path) {
  return nlohmann::json::parse(ReadFileToString(path));
}

TEST(ReportE2eTest, BuildLocalizeAndReport) {
  const fs::path root = fs::temp_directory_path() /
                        ("monomap_report_e2e_" + std::to_string(getpid()));
  fs::remove_all(root);
  SimulationOptions sim;
  sim.world = "lab-corner";
  sim.num_frames = 40;
  sim.width = 320;
  sim.height = 240;
  Simulate(sim, root / "data");
  const std::string data = (root / "data").string();
  const std::string map = (root / "map").string();

  RunResult r = RunMonomap("build " + data + " -o " + map + " -q --html " +
                           (root / "build.html").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string build_page = ReadFileToString(root / "build.html");
  EXPECT_GT(build_page.size(), 1000000u);  // three.js and Chart.js inlined
  EXPECT_NE(build_page.find("\"glb_base64\":\"Z2xURg"), std::string::npos);

  const fs::path run = root / "run";
  fs::create_directories(run);
  r = RunMonomap("localize " + map + " " + data +
                 " --method mcl --particles 200 -o " +
                 (run / "trajectory.txt").string() + " --report " +
                 (run / "report.json").string() + " --particles-out " +
                 (run / "particles.csv").string() + " --html " +
                 (root / "localize.html").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(ReadFileToString(root / "localize.html").find("\"particles\""),
            std::string::npos);

  r = RunMonomap("report " + map + " --dataset " + data + " --localization " +
                 run.string() + " -o " + (root / "report.html").string() +
                 " --json " + (root / "report.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json j = ReadJson(root / "report.json");
  EXPECT_EQ(j["problems"].size(), 0u);
  EXPECT_EQ(j["summary"]["frames"], 40);
  EXPECT_GE(j["planes"].size(), 1u);
  EXPECT_GT(j["points"]["plane"].size(),
            50u);  // the plane's points reach the page (99 of 40 frames)
  EXPECT_EQ(j["errors"]["series"][0]["error_m"].size(), 40u);
  EXPECT_EQ(j["features"]["frames"].size(), 3u);
  ASSERT_EQ(j["localization"].size(), 1u);
  EXPECT_EQ(j["localization"][0]["xyz"].size(), 3u * 40);
  EXPECT_EQ(j["localization"][0]["particles"]["steps"].size(), 40u);
  EXPECT_EQ(j["localization"][0]["report"]["steps"].size(), 40u);
  EXPECT_NE(
      j["provenance"]["command_line"].get<std::string>().find("report " + map),
      std::string::npos);

  // A broken map directory: named, exit status 1, the page still written.
  fs::remove(root / "map" / "points.ply");
  fs::resize_file(root / "map" / "map.glb", 100);
  fs::remove(root / "report.html");
  r = RunMonomap("report " + map + " -o " + (root / "report.html").string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("points.ply: missing"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("map.glb: truncated"), std::string::npos) << r.output;
  const std::string page = ReadFileToString(root / "report.html");
  EXPECT_NE(page.find("points.ply\",\"message\":\"missing\"}"),
            std::string::npos);
  fs::remove_all(root);
}

}  // namespace
}  // namespace monomap
