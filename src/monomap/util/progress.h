// A progress bar on stderr for long work, and a wall-clock timer.
#pragma once

#include <chrono>
#include <cstddef>
#include <mutex>
#include <string>

namespace monomap {

// Thread-safe progress bar. Draws only when stderr is a terminal or when
// forced, and at most ~10 times a second, so it never slows the work.
class ProgressBar {
 public:
  ProgressBar(std::string label, size_t total, bool enabled = true);
  ~ProgressBar();
  // Adds `n` finished items.
  void Advance(size_t n = 1);
  // Draws the final state and a newline.
  void Finish();

 private:
  void Draw(bool force);
  std::string label_;
  size_t total_;
  size_t done_ = 0;
  bool enabled_;
  bool finished_ = false;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
  std::mutex mutex_;
};

// Wall-clock stopwatch.
class Timer {
 public:
  Timer() : start_(std::chrono::steady_clock::now()) {}
  double ElapsedSeconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                         start_)
        .count();
  }
  void Restart() { start_ = std::chrono::steady_clock::now(); }

 private:
  std::chrono::steady_clock::time_point start_;
};

}  // namespace monomap
