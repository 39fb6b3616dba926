// libFuzzer target: a dataset directory (LoadDataset). The input holds the
// text files, separated by "----" lines, in the order of kFiles; a missing or
// empty part means the file is absent. rgb/000000.png..000002.png exist
// (64x48 grey) so that rgb.txt lines can name real images.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string_view>

#include "fuzz/fuzz_util.h"
#include "monomap/io/dataset.h"

namespace {

constexpr const char* kFiles[] = {"rgb.txt",         "odometry.txt",
                                  "odometry2d.txt",  "groundtruth.txt",
                                  "camera.yaml",     "camera_mount.yaml"};
constexpr size_t kNumFiles = sizeof(kFiles) / sizeof(kFiles[0]);

std::filesystem::path DatasetDir() {
  static const std::filesystem::path dir = [] {
    const auto d = monomap::fuzz::ScratchDir() / "dataset";
    std::filesystem::create_directories(d / "rgb");
    const cv::Mat image(48, 64, CV_8UC1, cv::Scalar(128));
    for (const char* name : {"000000.png", "000001.png", "000002.png"}) {
      cv::imwrite((d / "rgb" / name).string(), image);
    }
    return d;
  }();
  return dir;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  const auto dir = DatasetDir();
  const auto parts = monomap::fuzz::SplitParts(input, kNumFiles);
  for (size_t i = 0; i < kNumFiles; ++i) {
    std::filesystem::remove(dir / kFiles[i]);
    if (!parts[i].empty()) monomap::fuzz::WriteFile(dir / kFiles[i], parts[i]);
  }
  return monomap::fuzz::RunParser([&] { monomap::LoadDataset(dir); });
}
