#include "monomap/util/progress.h"

#include <unistd.h>

#include <cstdio>

namespace monomap {

ProgressBar::ProgressBar(std::string label, size_t total, bool enabled)
    : label_(std::move(label)),
      total_(total),
      enabled_(enabled && isatty(fileno(stderr))),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_) {}

ProgressBar::~ProgressBar() { Finish(); }

void ProgressBar::Advance(size_t n) {
  std::lock_guard<std::mutex> lock(mutex_);
  done_ += n;
  Draw(false);
}

void ProgressBar::Finish() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (finished_) return;
  finished_ = true;
  if (!enabled_) return;
  Draw(true);
  std::fputc('\n', stderr);
}

void ProgressBar::Draw(bool force) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  if (!force && now - last_draw_ < std::chrono::milliseconds(100)) return;
  last_draw_ = now;
  const double fraction =
      total_ == 0 ? 1.0 : static_cast<double>(done_) / total_;
  constexpr int kWidth = 30;
  const int filled = static_cast<int>(fraction * kWidth + 0.5);
  const double seconds = std::chrono::duration<double>(now - start_).count();
  std::fprintf(stderr, "\r%-14s [%.*s%*s] %zu/%zu %.1fs", label_.c_str(),
               filled, "##############################", kWidth - filled, "",
               done_, total_, seconds);
  std::fflush(stderr);
}

}  // namespace monomap
