// libFuzzer target: images through io/image_file (ReadImageFile, grey and colour).
#include <cstddef>
#include <cstdint>
#include <opencv2/imgcodecs.hpp>
#include <string_view>

#include "fuzz/fuzz_util.h"
#include "monomap/io/image_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  const auto path = monomap::fuzz::ScratchDir() / "image.png";
  monomap::fuzz::WriteFile(path, input);
  monomap::fuzz::RunParser([&] { monomap::ReadImageFile(path, cv::IMREAD_GRAYSCALE); });
  return monomap::fuzz::RunParser([&] { monomap::ReadImageFile(path, cv::IMREAD_COLOR); });
}
