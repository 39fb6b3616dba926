// monomap: mapping and localization with one camera and wheel odometry.
//
// Exit status: 0 success, 1 bad input data, 2 bad command line, 3 a stage
// failed or output could not be written, 4 unexpected internal error.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>

#include "monomap/exe/commands.h"
#include "monomap/util/error.h"
#include "monomap/util/runtime.h"

int main(int argc, char** argv) {
  // One OpenCV thread (oneTBB does the parallelism) and an allocator that
  // reuses freed image buffers: see util/runtime.h.
  monomap::ConfigureRuntime();
  CLI::App app{
      "monomap: dense planar maps and localization from one camera and "
      "odometry"};
  app.require_subcommand(1);
  monomap::RegisterBuildCommand(app);
  monomap::RegisterEvalCommand(app);
  monomap::RegisterSimulateCommand(app);
  monomap::RegisterRenderCommand(app);
  monomap::RegisterLocalizeCommand(app);
  monomap::RegisterCalibrateCommand(app);
  monomap::RegisterDemoCommand(app);
  monomap::RegisterReportCommand(app);
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
