// Reading images with a check that the file is whole. OpenCV decodes a
// truncated JPEG without an error (libjpeg fills the missing rows with
// grey and warns on stderr), so a half-copied dataset would be used
// silently; a truncated PNG fails, but only after libpng printed its own
// message. The end markers of both formats are checked first.
#pragma once

#include <cstdint>
#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace monomap {

// Limits on decoded images (textures, dataset frames, map cameras): a small
// compressed file can claim a huge size. docs/reliability.md.
inline constexpr int kMaxImageSide = 16384;
inline constexpr int64_t kMaxImagePixels = int64_t{64} << 20;  // 64 Mpx

// "" if a width x height image is within the limits, else why not.
std::string ImageSizeLimitError(int64_t width, int64_t height);

// Decodes the image at `path` with cv::imdecode `flags`. Throws InputError
// naming the file if it is not a regular file or cannot be read, is a PNG
// without its IEND chunk or a JPEG without its end-of-image marker, claims
// a size beyond the limits in its header (checked before decoding), or
// cannot be decoded. Only PNG, JPEG and PNM (P1-P6) are read: other formats
// could make OpenCV allocate an unchecked size.
cv::Mat ReadImageFile(const std::filesystem::path& path, int flags);

// The same checks and decoding for an image held in memory (e.g. a bag's
// CompressedImage); `where` names it in errors (a file, or file and topic).
cv::Mat DecodeImageBytes(const std::vector<uint8_t>& data, int flags,
                         const std::string& where);

}  // namespace monomap
