// Shared helpers of the libFuzzer targets: the parsers take paths, so each
// input is written to a per-process scratch directory first. monomap's typed
// errors (util/error.h) are the expected answer to bad input; anything else
// (another exception, a crash, UB, a hang, OOM) escapes and is a finding.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include "monomap/util/error.h"

namespace monomap::fuzz {

// A directory removed when the process exits normally: libFuzzer ends a
// timed or counted run with exit(), which runs static destructors.
class ScopedScratchDir {
 public:
  explicit ScopedScratchDir(std::filesystem::path path) : path_(std::move(path)) {
    std::filesystem::create_directories(path_);
  }
  ~ScopedScratchDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  ScopedScratchDir(const ScopedScratchDir&) = delete;
  ScopedScratchDir& operator=(const ScopedScratchDir&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

// A scratch directory unique to this process, created once and removed at
// exit (a crash leaves it, next to the reproducer).
inline const std::filesystem::path& ScratchDir() {
  static const ScopedScratchDir dir(std::filesystem::temp_directory_path() /
                                    ("monomap-fuzz-" + std::to_string(getpid())));
  return dir.path();
}

inline void WriteFile(const std::filesystem::path& path, std::string_view data) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(data.data(), static_cast<std::streamsize>(data.size()));
}

// Splits `data` into at most `n` parts at lines "----" so that one input can
// describe several files of a directory.
inline std::vector<std::string> SplitParts(std::string_view data, size_t n) {
  std::vector<std::string> parts(1);
  size_t pos = 0;
  while (pos <= data.size()) {
    size_t end = data.find('\n', pos);
    if (end == std::string_view::npos) end = data.size();
    std::string_view line = data.substr(pos, end - pos);
    if (line == "----" && parts.size() < n) {
      parts.emplace_back();
    } else {
      parts.back().append(line);
      if (end < data.size()) parts.back().push_back('\n');
    }
    pos = end + 1;
  }
  parts.resize(n);
  return parts;
}

// Runs `parse`, accepting monomap's typed errors as a correct outcome.
template <typename F>
int RunParser(F&& parse) {
  try {
    parse();
  } catch (const monomap::Error&) {
  }
  return 0;
}

}  // namespace monomap::fuzz
