// monomap demo [-o DIR] [--frames N] [--seed N] [--width W --height H]:
// simulate, map, evaluate (DIR/report.json) and write the report page of
// the map, its dataset and the localized traversal (DIR/report.html,
// self-contained).
#include <cstdio>
#include <memory>

#include "monomap/exe/commands.h"
#include "monomap/util/file.h"
#include "monomap/pipelines/demo.h"
#include "monomap/report/html_page.h"

namespace monomap {
namespace {

// The report page of the demo: the map and its dataset, the two
// localization runs, and the evaluation's figures.
std::filesystem::path WriteDemoPage(const DemoReport& r, const DemoOptions& o) {
  ReportInputs in;
  in.map_dir = r.map_dir;
  in.dataset_dir = r.dataset_dir;
  in.title = "monomap demo: " + o.world;
  in.command_line = CurrentCommandLine();
  in.extra = r.ToJson();
  for (const DemoLocalizationRun& run : r.localization.runs) {
    LocalizationRunData data;
    data.name = run.name;
    data.sources = {r.localization.dataset_dir.string()};
    data.trajectory = run.trajectory;
    data.groundtruth = r.localization.groundtruth;
    data.particles = run.particles;
    data.report = {{"steps", nlohmann::json::array()}};
    for (const LocalizerStepStats& s : run.report.steps) {
      data.report["steps"].push_back({{"particles", s.particles}});
    }
    in.localization.push_back(std::move(data));
  }
  const std::filesystem::path html = o.output_dir / "report.html";
  ThrowIfProblems(WriteReport(in, html), html);
  return html;
}

}  // namespace

void RegisterDemoCommand(CLI::App& app) {
  struct Args {
    std::string output = "out/demo";
    bool quiet = false;
    bool no_localization = false;
  };
  auto args = std::make_shared<Args>();
  auto o = std::make_shared<DemoOptions>();
  CLI::App* cmd = app.add_subcommand(
      "demo",
      "Simulate a world, build its map, evaluate it against the ground "
      "truth and write an HTML report");
  cmd->add_option("-o,--output", args->output,
                  "Output directory (dataset/, map/, report.html, "
                  "report.json)")
      ->capture_default_str();
  cmd->add_option("--world", o->world, "Simulated world")
      ->capture_default_str();
  cmd->add_option("--frames", o->num_frames, "Number of frames")
      ->capture_default_str();
  cmd->add_option("--seed", o->seed, "Seed of the simulation")
      ->capture_default_str();
  cmd->add_option("--width", o->width, "Image width")->capture_default_str();
  cmd->add_option("--height", o->height, "Image height")->capture_default_str();
  cmd->add_flag("-q,--quiet", args->quiet, "No progress output");
  cmd->add_option("--localization-frames", o->localization.num_frames,
                  "Frames of the second traversal that is localized")
      ->capture_default_str();
  cmd->add_option("--particles", o->localization.particles,
                  "Particle budget of MCL and MCC")
      ->capture_default_str();
  cmd->add_flag("--no-localization", args->no_localization,
                "Map and evaluate only");
  cmd->callback([args, o]() {
    CheckOutputDirectory(args->output, "demo", {});
    MarkOutputDirectory(args->output, "demo");
    o->output_dir = args->output;
    o->show_progress = !args->quiet;
    o->localization.enabled = !args->no_localization;
    const DemoReport r = RunDemo(*o);
    const std::filesystem::path html = WriteDemoPage(r, *o);
    const StructureAccuracy& st = r.structure;
    const auto& pe = st.point_error_on_planes.absolute_m;
    std::printf(
        "monomap demo: %d frames, %d landmarks, %d planes found (%d true "
        "planes observed, recall %.0f%%, precision %.0f%%)\n"
        "  point error on planes: median %.1f mm, p90 %.1f mm (median "
        "%.2f%% of depth)\n"
        "  ATE (first-pose aligned, rms): refined %.1f cm, odometry %.1f cm\n",
        r.frames, r.landmarks, st.fitted_planes, st.observed_true_planes,
        100 * st.recall, 100 * st.precision, pe.median * 1000, pe.p90 * 1000,
        st.point_error_on_planes.relative_percent.median,
        r.ate_refined.translation_m.rms * 100,
        r.ate_odometry.translation_m.rms * 100);
    const DemoLocalization& loc = r.localization;
    if (!loc.runs.empty()) {
      std::printf(
          "  texture fidelity on the second traversal: NCC median "
          "%.3f, PSNR median %.1f dB\n",
          loc.fidelity.ncc.median, loc.fidelity.psnr_db.median);
      for (const DemoLocalizationRun& run : loc.runs) {
        const LocalizationAccuracy& a = run.accuracy;
        std::printf(
            "  %s from a global start: %s, final error %.1f cm / "
            "%.2f deg, %.1f ms per update\n",
            run.name.c_str(),
            a.success
                ? ("localized from update " + std::to_string(a.converged_step))
                      .c_str()
                : "NOT localized",
            100 * a.final_translation_error_m, a.final_rotation_error_deg,
            1e3 * run.report.mean_step_seconds);
      }
    }
    std::printf("  total %.1f s\nreport: %s\n", r.total_seconds,
                html.string().c_str());
  });
}

}  // namespace monomap
