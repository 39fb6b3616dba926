// The runner of the bad-input catalogue (docs/reliability.md), shared by
// bad_input_test (datasets, maps) and bad_import_test (the importers): each
// case corrupts a copy of a good input and runs the `monomap` binary on it.
// Every case must end in under a minute with exit code 1 (bad input; never
// 4), a message naming the file (and line, field or topic), and no output.
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "tests/monomap_cli.h"

namespace monomap::test {

struct Case {
  std::string name;
  // Corrupts the copy of the good input (a file or a directory).
  std::function<void(const std::filesystem::path& input)> corrupt;
  // Text the message must contain (the file, ...); "INPUT" in it stands
  // for the path of the corrupted copy.
  std::string named;
  // Replaces "ARGS" in the command, if it has one.
  std::string args = "";
};

inline void ReplaceAll(std::string& text, const std::string& from,
                       const std::string& to) {
  for (size_t at = text.find(from); at != std::string::npos;
       at = text.find(from, at + to.size())) {
    text.replace(at, from.size(), to);
  }
}

// Runs `command` (INPUT, OUT and ARGS replaced) on a corrupted copy of
// `root`/`good` for each case and checks the outcome. `good` keeps its
// extension in the copy (a bag is recognized by it).
inline void RunCatalogue(const std::filesystem::path& root,
                         const std::string& good, const std::string& command,
                         const std::vector<Case>& cases,
                         const std::string& out_extension = "") {
  namespace fs = std::filesystem;
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const fs::path input =
        root / ("in_" + c.name + fs::path(good).extension().string());
    fs::remove_all(input);
    fs::copy(root / good, input, fs::copy_options::recursive);
    c.corrupt(input);
    const fs::path out = root / ("out_" + c.name + out_extension);
    std::string line = command, named = c.named;
    ReplaceAll(line, "INPUT", input.string());
    ReplaceAll(line, "OUT", out.string());
    ReplaceAll(line, "ARGS", c.args);
    ReplaceAll(named, "INPUT", input.string());
    const auto start = std::chrono::steady_clock::now();
    const RunResult r = RunMonomap(line);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
            .count();
    EXPECT_EQ(r.exit_code, 1) << r.output;  // bad input, never 4
    EXPECT_EQ(r.output.find("internal error"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find(named), std::string::npos)
        << "expected: " << named << "\n"
        << r.output;
    EXPECT_LT(seconds, 60.0);
    EXPECT_FALSE(fs::exists(out)) << "output written";
    fs::remove_all(input);
  }
}

}  // namespace monomap::test
