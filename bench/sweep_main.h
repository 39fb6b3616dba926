// The shared tail of the command-line sweeps' main(): parse the options,
// run, and turn errors into exit statuses (2: usage or options, 3: any
// other failure), as the monomap binary does.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>

#include "monomap/util/error.h"

namespace monomap {

template <typename Run>
int ParseAndRunSweep(CLI::App& app, int argc, char** argv, const char* name,
                     Run&& run) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  try {
    return run();
  } catch (const OptionsError& e) {
    std::fprintf(stderr, "%s: error: %s\n", name, e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: error: %s\n", name, e.what());
    return 3;
  }
}

}  // namespace monomap
