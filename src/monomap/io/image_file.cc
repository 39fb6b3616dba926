#include "monomap/io/image_file.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <opencv2/imgcodecs.hpp>
#include <vector>

#include "monomap/util/error.h"

namespace monomap {
namespace {

bool StartsWith(const std::vector<uint8_t>& data,
                std::initializer_list<uint8_t> prefix) {
  return data.size() >= prefix.size() &&
         std::equal(prefix.begin(), prefix.end(), data.begin());
}

// The last chunk of every PNG: length 0, type IEND, its CRC.
constexpr std::array<uint8_t, 12> kPngEnd = {
    0x00, 0x00, 0x00, 0x00, 0x49, 0x45, 0x4E, 0x44, 0xAE, 0x42, 0x60, 0x82};
// Writers may pad a JPEG after its end-of-image marker; look this far back.
constexpr size_t kJpegTailBytes = 4096;

}  // namespace

cv::Mat ReadImageFile(const std::filesystem::path& path, int flags) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string() + ": cannot open image");
  const std::vector<uint8_t> data((std::istreambuf_iterator<char>(in)),
                                  std::istreambuf_iterator<char>());
  if (in.bad()) throw InputError(path.string() + ": cannot read image");
  if (data.empty()) throw InputError(path.string() + ": image file is empty");
  if (StartsWith(data, {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'})) {
    if (data.size() < kPngEnd.size() ||
        !std::equal(kPngEnd.begin(), kPngEnd.end(),
                    data.end() - kPngEnd.size())) {
      throw InputError(path.string() +
                       ": truncated PNG (no IEND chunk at the end)");
    }
  } else if (StartsWith(data, {0xFF, 0xD8, 0xFF})) {
    const size_t from =
        data.size() > kJpegTailBytes ? data.size() - kJpegTailBytes : 0;
    bool has_end = false;
    for (size_t i = data.size() - 1; i > from && !has_end; --i) {
      has_end = data[i - 1] == 0xFF && data[i] == 0xD9;
    }
    if (!has_end) {
      throw InputError(path.string() +
                       ": truncated JPEG (no end-of-image marker)");
    }
  }
  cv::Mat image = cv::imdecode(data, flags);
  if (image.empty()) {
    throw InputError(path.string() + ": cannot decode image");
  }
  return image;
}

}  // namespace monomap
