#include "monomap/pipelines/demo.h"

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

// The small demo (60 frames at 320x240, 30 localized) written to a fresh
// directory named `name` in the temporary directory.
DemoOptions SmallDemo(const std::string& name) {
  DemoOptions o;
  o.output_dir = std::filesystem::temp_directory_path() /
                 (name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(o.output_dir);
  o.num_frames = 60;
  o.width = 320;
  o.height = 240;
  o.show_progress = false;
  o.localization.num_frames = 30;
  o.localization.particles = 500;
  return o;
}

// A small demo end to end: its figures say the map is close to the ground
// truth, and they are written to report.json.
TEST(DemoReportTest, SmallHallwayDemo) {
  const DemoOptions o = SmallDemo("monomap_demo_test");
  const std::filesystem::path dir = o.output_dir;
  const DemoReport r = RunDemo(o);

  EXPECT_EQ(r.frames, 60);
  // Exported (trusted) points: 195 at 320x240, where 1 px is 2 mrad and
  // the export leaves out the loosest third.
  EXPECT_GT(r.landmarks, 150);
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
  // 0.894-0.930 over bundle adjustment's variants (outlier solve at 2 or
  // 3 px or off, planar-base prior on or off) on this 60-frame 320x240 map.
  EXPECT_GT(loc.fidelity.ncc.median, 0.88);
  EXPECT_GT(loc.fidelity.psnr_db.median, 20.0);
  ASSERT_EQ(loc.runs.size(), 2u);
  for (const DemoLocalizationRun& run : loc.runs) {
    EXPECT_EQ(run.report.frames, 30) << run.name;
    EXPECT_EQ(run.accuracy.matched, 30) << run.name;
    EXPECT_EQ(run.particles.size(), 30u) << run.name;
    for (const auto& set : run.particles) {  // a subset of each set
      EXPECT_GT(set.size(), 0u) << run.name;
      EXPECT_LE(set.size(),
                static_cast<size_t>(o.localization.plotted_particles))
          << run.name;
    }
  }
  std::printf(
      "texture fidelity NCC %.3f, PSNR %.1f dB; MCL final %.3f m, "
      "MCC final %.3f m\n",
      loc.fidelity.ncc.median, loc.fidelity.psnr_db.median,
      loc.runs[0].accuracy.final_translation_error_m,
      loc.runs[1].accuracy.final_translation_error_m);

  ASSERT_TRUE(std::filesystem::exists(r.report_json));
  ASSERT_TRUE(std::filesystem::exists(dir / "map" / "map.json"));
  const nlohmann::json figures =
      nlohmann::json::parse(ReadFileToString(r.report_json));
  EXPECT_EQ(figures["counts"]["frames"], 60);
  EXPECT_EQ(figures["localization"]["runs"].size(), 2u);
  EXPECT_DOUBLE_EQ(figures["trajectory"]["ate_refined"]["translation_m"]["rms"]
                       .get<double>(),
                   r.ate_refined.translation_m.rms);
  std::filesystem::remove_all(dir);
}

// Plane growth on the small demo: its floor's fitted polygon reaches past
// the foot of a side wall the map lacks (a misplaced point). Growth keeps
// that outline as it was drawn and only adds cells, so the map rendered
// from the second traversal's poses matches its images as well as without
// growth; redrawing the floor as whole growth cells made that overhang a
// solid band over the wall's foot (NCC median 0.83).
TEST(DemoReportTest, GrownPlanesKeepTheSmallDemosTextureFidelity) {
  DemoOptions o = SmallDemo("monomap_demo_grow_test");
  ASSERT_TRUE(o.mapping.growth.enabled);  // the default
  const DemoReport r = RunDemo(o);
  int grown = 0;
  for (const auto& p : r.mapping["plane_growth"]["planes"]) {
    grown += p["cells_textured"].get<int>() + p["cells_plain"].get<int>();
  }
  EXPECT_GT(grown, 0);
  // Well above the band's 0.83 (the spread without it: SmallHallwayDemo).
  EXPECT_GT(r.localization.fidelity.ncc.median, 0.88);
  EXPECT_GT(r.localization.fidelity.coverage.median, 0.3);
  std::printf("grown cells %d; texture fidelity NCC %.3f, coverage %.3f\n",
              grown, r.localization.fidelity.ncc.median,
              r.localization.fidelity.coverage.median);
  std::filesystem::remove_all(o.output_dir);
}

}  // namespace
}  // namespace monomap
