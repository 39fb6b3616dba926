#include "monomap/report/html_page.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>

#include "monomap/util/error.h"
#include "monomap/util/file.h"

namespace monomap {
namespace {

size_t Count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t p = text.find(what); p != std::string::npos;
       p = text.find(what, p + what.size())) {
    ++n;
  }
  return n;
}

TEST(HtmlPageTest, TemplateWithLibrariesAndDataInlined) {
  const nlohmann::json data = {{"title", "x</script><b>y"},
                               {"planes", nlohmann::json::array()}};
  const std::string html = RenderReportHtml(data);
  // Every marker replaced; the libraries are there, whole.
  EXPECT_EQ(html.find("@REPORT_"), std::string::npos);
  EXPECT_EQ(html.find("@LIB_"), std::string::npos);
  for (const char* lib : {"three.js", "GLTFLoader.js", "OrbitControls.js",
                          "chart.js", "report.js", "report.css"}) {
    EXPECT_NE(html.find(std::string(ReportAsset(lib))), std::string::npos)
        << lib;
    EXPECT_GT(ReportAsset(lib).size(), 1000u) << lib;
  }
  EXPECT_NE(html.find("Chart.js v3"), std::string::npos);
  EXPECT_NE(html.find("GLTFLoader"), std::string::npos);
  // The data cannot close its script element: only the template's six
  // script elements end.
  EXPECT_EQ(Count(html, "</script>"), 6u);
  EXPECT_NE(html.find(R"("x<\/script><b>y")"), std::string::npos);
  // Self-contained: nothing loaded from elsewhere.
  EXPECT_EQ(Count(html, "src=\"http"), 0u);
  EXPECT_EQ(Count(html, "href=\"http"), 0u);
}

TEST(HtmlPageTest, ProblemsBecomeOneInputErrorNamingTheFiles) {
  EXPECT_NO_THROW(ThrowIfProblems({}, "r.html"));
  try {
    ThrowIfProblems({{"/m/points.ply", "missing"}, {"/m/map.glb", "bad"}},
                    "r.html");
    FAIL() << "no exception";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("/m/points.ply: missing"), std::string::npos);
    EXPECT_NE(what.find("/m/map.glb: bad"), std::string::npos);
    EXPECT_NE(what.find("r.html"), std::string::npos);
  }
}

TEST(HtmlPageTest, WriteReportWritesThePageEvenForAMissingMap) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() /
      ("monomap_html_test_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  ReportInputs in;
  in.map_dir = dir / "no_such_map";
  const auto problems = WriteReport(in, dir / "r.html", dir / "r.json");
  EXPECT_EQ(problems.size(), 4u);  // map.json, points, trajectory, glb
  const std::string html = ReadFileToString(dir / "r.html");
  EXPECT_NE(html.find("no_such_map/map.json"), std::string::npos);
  const nlohmann::json j =
      nlohmann::json::parse(ReadFileToString(dir / "r.json"));
  EXPECT_EQ(j["problems"].size(), 4u);
  EXPECT_FALSE(j.contains("glb_base64"));  // blobs stay in the page only
  EXPECT_EQ(j["map_files"][0]["link"], "no_such_map/trajectory.txt");
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace monomap
