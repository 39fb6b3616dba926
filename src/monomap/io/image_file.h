// Reading images with a check that the file is whole. OpenCV decodes a
// truncated JPEG without an error (libjpeg fills the missing rows with
// grey and warns on stderr), so a half-copied dataset would be used
// silently; a truncated PNG fails, but only after libpng printed its own
// message. The end markers of both formats are checked first.
#pragma once

#include <filesystem>
#include <opencv2/core.hpp>

namespace monomap {

// Decodes the image at `path` with cv::imdecode `flags`. Throws InputError
// naming the file if it cannot be read, is a PNG without its IEND chunk or
// a JPEG without its end-of-image marker, or cannot be decoded. Other
// formats are left to OpenCV.
cv::Mat ReadImageFile(const std::filesystem::path& path, int flags);

}  // namespace monomap
