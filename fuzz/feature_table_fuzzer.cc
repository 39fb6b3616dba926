// libFuzzer target: the feature table (ReadFeatureTable).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz/fuzz_util.h"
#include "monomap/io/feature_table.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  const auto path = monomap::fuzz::ScratchDir() / "features.txt";
  monomap::fuzz::WriteFile(path, input);
  return monomap::fuzz::RunParser([&] { monomap::ReadFeatureTable(path); });
}
