// Runs the `monomap` binary of the build (MONOMAP_BINARY) for the
// end-to-end tests: its exit code and its output.
#pragma once

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace monomap {

struct RunResult {
  int exit_code = -1;
  std::string output;  // stdout + stderr
};

inline RunResult RunMonomap(const std::string& args) {
  const std::string cmd = std::string(MONOMAP_BINARY) + " " + args + " 2>&1";
  RunResult r;
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return r;
  std::array<char, 4096> buf;
  size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), pipe)) > 0) {
    r.output.append(buf.data(), n);
  }
  const int status = pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

}  // namespace monomap
