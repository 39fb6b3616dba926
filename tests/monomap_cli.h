// Running the `monomap` binary from tests: to completion (exit code and
// output), or in the background (a pid to stop, signal and wait for).
#pragma once

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "monomap/sim/simulate.h"

namespace monomap::test {

struct RunResult {
  int exit_code = -1;  // -1 if killed by a signal
  std::string output;  // stdout + stderr
};

// Runs `monomap ARGS` (a shell command line) to completion; a run that
// hangs is killed after two minutes (exit code 137).
inline RunResult RunMonomap(const std::string& args) {
  const std::string cmd = "timeout -s KILL 120 " + std::string(MONOMAP_BINARY) +
                          " " + args + " 2>&1";
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

// Starts `monomap ARGS...` with stdout and stderr to `log` and the extra
// environment `env` ("NAME=value"). Returns its pid.
inline pid_t SpawnMonomap(const std::vector<std::string>& args,
                          const std::filesystem::path& log,
                          const std::vector<std::string>& env = {}) {
  const pid_t pid = fork();
  if (pid != 0) return pid;
  if (std::freopen(log.c_str(), "w", stdout) == nullptr) _exit(120);
  dup2(fileno(stdout), fileno(stderr));
  for (const std::string& e : env) putenv(const_cast<char*>(e.c_str()));
  std::vector<char*> argv;
  argv.push_back(const_cast<char*>(MONOMAP_BINARY));
  for (const std::string& a : args)
    argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  execv(MONOMAP_BINARY, argv.data());
  _exit(121);
}

// Waits until `pid` stops (SIGSTOP) or ends, up to `seconds`. Returns true
// if it stopped.
inline bool WaitUntilStopped(pid_t pid, int seconds = 120) {
  const auto until =
      std::chrono::steady_clock::now() + std::chrono::seconds(seconds);
  while (std::chrono::steady_clock::now() < until) {
    int status = 0;
    const pid_t r = waitpid(pid, &status, WUNTRACED | WNOHANG);
    if (r == pid) return WIFSTOPPED(status);
    if (r < 0) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

// Waits for `pid` to end; its exit code, or 128 + signal if killed.
inline int WaitForExit(pid_t pid) {
  int status = 0;
  if (waitpid(pid, &status, 0) != pid) return -1;
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// A fresh, empty folder under the temp directory, unique to this process,
// holding a simulated lab-corner dataset "data" of `frames` frames.
inline std::filesystem::path FolderWithDataset(const std::string& prefix,
                                               int frames, int width,
                                               int height) {
  const std::filesystem::path root = std::filesystem::temp_directory_path() /
                                     (prefix + "_" + std::to_string(getpid()));
  std::filesystem::remove_all(root);
  std::filesystem::create_directories(root);
  SimulationOptions sim;
  sim.world = "lab-corner";
  sim.num_frames = frames;
  sim.width = width;
  sim.height = height;
  Simulate(sim, root / "data");
  return root;
}

}  // namespace monomap::test
