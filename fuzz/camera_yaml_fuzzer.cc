// libFuzzer target: camera.yaml (ReadCameraYaml).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz/fuzz_util.h"
#include "monomap/io/dataset.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  const auto path = monomap::fuzz::ScratchDir() / "camera.yaml";
  monomap::fuzz::WriteFile(path, input);
  return monomap::fuzz::RunParser([&] { monomap::ReadCameraYaml(path); });
}
