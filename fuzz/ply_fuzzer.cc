// libFuzzer target: points.ply (ReadPlyPoints and ReadLandmarksPly).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz/fuzz_util.h"
#include "monomap/io/ply.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  const auto path = monomap::fuzz::ScratchDir() / "points.ply";
  monomap::fuzz::WriteFile(path, input);
  monomap::fuzz::RunParser([&] { monomap::ReadPlyPoints(path); });
  return monomap::fuzz::RunParser([&] { monomap::ReadLandmarksPly(path); });
}
