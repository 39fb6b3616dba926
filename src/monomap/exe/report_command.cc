// monomap report MAP_DIR [--dataset D] [--localization RUN]... -o
// report.html [--json report.json]: one self-contained HTML page of a map
// (3D view, trajectory, errors, textures, tracks, provenance). Missing or
// corrupt input files are named on the page and make the exit status 1;
// the page is written either way.
#include <memory>

#include "monomap/exe/commands.h"
#include "monomap/report/html_page.h"
#include "monomap/report/localization_run.h"

namespace monomap {

void RegisterReportCommand(CLI::App& app) {
  struct Args {
    std::string map_dir, dataset, output, json, title;
    std::vector<std::string> localization;
  };
  auto a = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "report",
      "Write a self-contained HTML report of a map (3D view, "
      "trajectory, errors, textures, tracked features)");
  cmd->add_option("map", a->map_dir, "Map directory")->required();
  cmd->add_option("-o,--output", a->output, "HTML page to write")->required();
  cmd->add_option("--dataset", a->dataset,
                  "Dataset the map was built from (ground truth, odometry, "
                  "images for the tracked features)");
  cmd->add_option("--localization", a->localization,
                  "A localization run (repeatable): a directory with "
                  "trajectory.txt [report.json particles.csv "
                  "groundtruth.txt], or files TRAJ.txt[,R.json][,P.csv]"
                  "[,GT.txt] as written by 'monomap localize'");
  cmd->add_option("--json", a->json, "Also write the report data as JSON");
  cmd->add_option("--title", a->title, "Page title");
  cmd->callback([a]() {
    ReportInputs in;
    in.map_dir = a->map_dir;
    in.dataset_dir = a->dataset;
    in.title = a->title;
    in.command_line = CurrentCommandLine();
    for (const std::string& spec : a->localization) {
      in.localization.push_back(ReadLocalizationRun(spec, &in.problems));
    }
    const std::vector<ReportProblem> problems =
        WriteReport(in, a->output, a->json);
    std::fprintf(stderr, "monomap: report -> %s\n", a->output.c_str());
    ThrowIfProblems(problems, a->output);
  });
}

}  // namespace monomap
