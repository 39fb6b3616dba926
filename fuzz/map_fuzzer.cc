// libFuzzer target: a map directory (ReadMap). Parts separated by "----" lines: map.json, trajectory.txt, points.ply.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string_view>

#include "fuzz/fuzz_util.h"
#include "monomap/io/map_format.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  const auto dir = monomap::fuzz::ScratchDir() / "map";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const auto parts = monomap::fuzz::SplitParts(input, 3);
  monomap::fuzz::WriteFile(dir / "map.json", parts[0]);
  if (!parts[1].empty()) monomap::fuzz::WriteFile(dir / "trajectory.txt", parts[1]);
  if (!parts[2].empty()) monomap::fuzz::WriteFile(dir / "points.ply", parts[2]);
  return monomap::fuzz::RunParser([&] { monomap::ReadMap(dir); });
}
