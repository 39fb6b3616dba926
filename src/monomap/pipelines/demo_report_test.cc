#include "monomap/pipelines/demo_report.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "monomap/util/error.h"
#include "monomap/util/file.h"

namespace monomap {
namespace {

size_t CountOccurrences(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t pos = text.find(what); pos != std::string::npos;
       pos = text.find(what, pos + what.size())) {
    ++n;
  }
  return n;
}

TEST(DemoOptionsTest, RejectsBadValues) {
  DemoOptions o;
  EXPECT_NO_THROW(o.Check());
  o.world = "moon";
  EXPECT_THROW(o.Check(), OptionsError);
  o = DemoOptions();
  o.num_frames = 5;
  EXPECT_THROW(o.Check(), OptionsError);
  o = DemoOptions();
  o.structure.max_match_angle_deg = 0;
  EXPECT_THROW(o.Check(), OptionsError);
  o = DemoOptions();
  o.localization.num_frames = 1;
  EXPECT_THROW(o.Check(), OptionsError);
  o.localization.enabled = false;  // not checked when not run
  EXPECT_NO_THROW(o.Check());
}

// A small demo end to end: the report is written, self-contained, and its
// figures say the map is close to the ground truth.
TEST(DemoReportTest, SmallHallwayDemo) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() /
      ("monomap_demo_test_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  DemoOptions o;
  o.output_dir = dir;
  o.num_frames = 60;
  o.width = 320;
  o.height = 240;
  o.show_progress = false;
  o.localization.num_frames = 30;
  o.localization.particles = 500;
  const DemoReport r = RunDemo(o);

  EXPECT_EQ(r.frames, 60);
  EXPECT_GT(r.landmarks, 200);
  EXPECT_GE(r.structure.fitted_planes, 1);
  EXPECT_GE(r.structure.observed_true_planes, 1);
  EXPECT_GT(r.structure.recall, 0.0);
  EXPECT_GE(r.structure.precision, 0.5);
  // Points on fitted planes lie on the true structure within centimetres.
  EXPECT_GT(r.structure.point_error_on_planes.absolute_m.count, 100u);
  EXPECT_LT(r.structure.point_error_on_planes.absolute_m.median, 0.03);
  EXPECT_LT(r.structure.point_error_on_planes.relative_percent.median, 3.0);
  // The refined trajectory is at least as good as odometry (small slack).
  EXPECT_EQ(r.ate_refined.matched, 60u);
  EXPECT_LT(r.ate_refined.translation_m.rms, 0.05);
  EXPECT_LE(r.ate_refined.translation_m.rms,
            r.ate_odometry.translation_m.rms + 0.005);

  // The second traversal: the map rendered from its true poses matches its
  // images (texture fidelity), and both methods ran every frame.
  const DemoLocalization& loc = r.localization;
  EXPECT_EQ(loc.frames, 30);
  EXPECT_GE(loc.fidelity.frames.size(), 4u);
  EXPECT_GT(loc.fidelity.ncc.median, 0.9);
  EXPECT_GT(loc.fidelity.psnr_db.median, 20.0);
  ASSERT_EQ(loc.runs.size(), 2u);
  for (const DemoLocalizationRun& run : loc.runs) {
    EXPECT_EQ(run.report.frames, 30) << run.name;
    EXPECT_EQ(run.accuracy.matched, 30) << run.name;
    EXPECT_EQ(run.particles_xy.size(), 30u) << run.name;
  }
  std::printf(
      "texture fidelity NCC %.3f, PSNR %.1f dB; MCL final %.3f m, "
      "MCC final %.3f m\n",
      loc.fidelity.ncc.median, loc.fidelity.psnr_db.median,
      loc.runs[0].accuracy.final_translation_error_m,
      loc.runs[1].accuracy.final_translation_error_m);

  ASSERT_TRUE(std::filesystem::exists(r.report_json));
  ASSERT_TRUE(std::filesystem::exists(dir / "map" / "map.json"));
  const std::string html = ReadFileToString(r.report_html);
  // 3 track frames, 3 real + 3 rendered views, one texture per plane.
  EXPECT_EQ(CountOccurrences(html, "<img "),
            static_cast<size_t>(9 + r.structure.fitted_planes));
  EXPECT_EQ(CountOccurrences(html, "src=\"data:image/png;base64,"),
            static_cast<size_t>(9 + r.structure.fitted_planes));
  EXPECT_EQ(CountOccurrences(html, "src=\"http"), 0u);
  EXPECT_EQ(CountOccurrences(html, "href=\"http"), 0u);
  // Points, trajectory, error; localization error, particle counts and
  // particle snapshots.
  EXPECT_GE(CountOccurrences(html, "<svg "), 8u);
  EXPECT_NE(html.find("id=\"localization\""), std::string::npos);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace monomap
