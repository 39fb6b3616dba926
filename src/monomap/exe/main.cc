// monomap: mapping and localization with one camera and wheel odometry.
//
// Exit status: 0 success, 1 bad input data, 2 bad command line, 3 a stage
// failed or output could not be written, 4 unexpected internal error.
#include <tbb/global_control.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <memory>
#include <string>

#include "monomap/exe/commands.h"
#include "monomap/exe/interrupt.h"
#include "monomap/util/error.h"
#include "monomap/util/runtime.h"
#include "monomap/version.h"

namespace {

// CLI11 reports an unknown first word only as "A subcommand is required":
// name it and list the subcommands instead. Returns false if it is unknown.
bool CheckSubcommandName(CLI::App& app, int argc, char** argv) {
  if (argc < 2 || argv[1][0] == '-') return true;
  std::string names;
  for (const CLI::App* sub :
       app.get_subcommands([](CLI::App*) { return true; })) {
    if (sub->get_name() == argv[1]) return true;
    names += (names.empty() ? "" : ", ") + sub->get_name();
  }
  std::fprintf(stderr, "monomap: error: unknown subcommand '%s' (one of: %s)\n",
               argv[1], names.c_str());
  return false;
}

}  // namespace

int main(int argc, char** argv) {
  // Before any thread exists: see exe/interrupt.h.
  monomap::InstallInterruptCleanup();
  // One OpenCV thread (oneTBB does the parallelism) and an allocator that
  // reuses freed image buffers: see util/runtime.h.
  monomap::ConfigureRuntime();
  CLI::App app{
      "monomap: dense planar maps and localization from one camera and "
      "odometry"};
  app.require_subcommand(1);
  // Global, so that every command takes it (also after the subcommand:
  // fallthrough). Set while parsing, before the command's callback runs.
  app.fallthrough();
  std::unique_ptr<tbb::global_control> thread_limit;
  app.add_option_function<int>(
         "--threads",
         [&thread_limit](int n) {
           thread_limit = std::make_unique<tbb::global_control>(
               tbb::global_control::max_allowed_parallelism,
               static_cast<size_t>(n));
         },
         "Worker threads (oneTBB); results do not depend on it "
         "(default: all cores)")
      ->check(CLI::Range(1, 1024));
  app.set_version_flag("--version", std::string("monomap ") +
                                        monomap::kVersion + " (commit " +
                                        monomap::kGitCommit + ")");
  monomap::RegisterBuildCommand(app);
  monomap::RegisterEvalCommand(app);
  monomap::RegisterSimulateCommand(app);
  monomap::RegisterRenderCommand(app);
  monomap::RegisterLocalizeCommand(app);
  monomap::RegisterCalibrateCommand(app);
  monomap::RegisterDemoCommand(app);
  monomap::RegisterExportCommand(app);
  monomap::RegisterImportCommand(app);
  monomap::RegisterReportCommand(app);
  if (!CheckSubcommandName(app, argc, argv)) return 2;
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  } catch (const monomap::InputError& e) {
    std::fprintf(stderr, "monomap: error: %s\n", e.what());
    return 1;
  } catch (const monomap::OptionsError& e) {
    std::fprintf(stderr, "monomap: error: %s\n", e.what());
    return 2;
  } catch (const monomap::Error& e) {
    std::fprintf(stderr, "monomap: error: %s\n", e.what());
    return 3;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "monomap: internal error: %s\n", e.what());
    return 4;
  }
  return 0;
}
