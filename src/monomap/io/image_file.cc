#include "monomap/io/image_file.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <csetjmp>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

// After <cstdio>: jpeglib.h needs FILE and size_t.
#include <jpeglib.h>

#include <vector>

#include "monomap/util/error.h"
#include "monomap/util/file.h"

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

uint32_t BigEndian(const std::vector<uint8_t>& data, size_t at, int bytes) {
  uint32_t v = 0;
  for (int i = 0; i < bytes; ++i) v = (v << 8) | data[at + i];
  return v;
}

// Width and height from a PNG's IHDR chunk (right after the signature).
bool PngSize(const std::vector<uint8_t>& data, int64_t* w, int64_t* h) {
  if (data.size() < 24 || BigEndian(data, 12, 4) != 0x49484452) return false;
  *w = BigEndian(data, 16, 4);
  *h = BigEndian(data, 20, 4);
  return true;
}

// Width and height from a PNM header (P1..P6): the magic, then width and
// height as decimal numbers between whitespace and '#' comments.
bool PnmSize(const std::vector<uint8_t>& data, int64_t* w, int64_t* h) {
  if (data.size() < 3 || data[0] != 'P' || data[1] < '1' || data[1] > '6') {
    return false;
  }
  size_t i = 2;
  int64_t v[2] = {0, 0};
  for (int64_t& x : v) {
    while (i < data.size() && (std::isspace(data[i]) || data[i] == '#')) {
      if (data[i] == '#') {
        while (i < data.size() && data[i] != '\n') ++i;
      } else {
        ++i;
      }
    }
    if (i >= data.size() || !std::isdigit(data[i])) return false;
    // Stops growing far beyond any limit; the size check then refuses it.
    while (i < data.size() && std::isdigit(data[i]) && x < (int64_t{1} << 40)) {
      x = 10 * x + (data[i++] - '0');
    }
  }
  *w = v[0];
  *h = v[1];
  return true;
}

// Width and height from a JPEG's first start-of-frame marker.
bool JpegSize(const std::vector<uint8_t>& data, int64_t* w, int64_t* h) {
  size_t i = 2;
  while (i + 9 < data.size()) {
    if (data[i] != 0xFF) return false;
    const uint8_t marker = data[i + 1];
    if (marker == 0xFF) {  // fill byte
      ++i;
      continue;
    }
    const bool sof = marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 &&
                     marker != 0xC8 && marker != 0xCC;
    if (sof) {
      *h = BigEndian(data, i + 5, 2);
      *w = BigEndian(data, i + 7, 2);
      return true;
    }
    i += 2 + BigEndian(data, i + 2, 2);
  }
  return false;
}

// libjpeg's error handling: errors jump back to the caller, warnings (such
// as "Premature end of JPEG file", after which libjpeg fills the missing
// rows with grey) are counted and the first is kept, none is printed.
struct JpegErrors {
  jpeg_error_mgr manager;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
};

void JpegErrorExit(j_common_ptr cinfo) {
  auto* errors = reinterpret_cast<JpegErrors*>(cinfo->err);
  (*cinfo->err->format_message)(cinfo, errors->message);
  std::longjmp(errors->jump, 1);
}

void JpegEmitMessage(j_common_ptr cinfo, int level) {
  if (level >= 0) return;  // trace messages
  auto* errors = reinterpret_cast<JpegErrors*>(cinfo->err);
  if (cinfo->err->num_warnings++ == 0) {
    (*cinfo->err->format_message)(cinfo, errors->message);
  }
}

// Decodes the whole entropy-coded data of a JPEG (at 1/8 scale, which
// still reads every block) and returns libjpeg's first error or warning,
// "" if there is none. Plain C inside: no C++ object lives across the
// setjmp.
std::string JpegDecodeProblem(const std::vector<uint8_t>& data) {
  jpeg_decompress_struct cinfo;
  JpegErrors errors;
  errors.message[0] = '\0';
  cinfo.err = jpeg_std_error(&errors.manager);
  errors.manager.error_exit = JpegErrorExit;
  errors.manager.emit_message = JpegEmitMessage;
  unsigned char* row = nullptr;
  if (setjmp(errors.jump) != 0) {
    std::free(row);
    jpeg_destroy_decompress(&cinfo);
    return errors.message;
  }
  jpeg_create_decompress(&cinfo);
  jpeg_mem_src(&cinfo, data.data(), static_cast<unsigned long>(data.size()));
  jpeg_read_header(&cinfo, TRUE);
  cinfo.scale_num = 1;
  cinfo.scale_denom = 8;
  cinfo.dct_method = JDCT_IFAST;
  cinfo.do_fancy_upsampling = FALSE;
  jpeg_start_decompress(&cinfo);
  row = static_cast<unsigned char*>(
      std::malloc(cinfo.output_width * cinfo.output_components));
  while (row != nullptr && cinfo.output_scanline < cinfo.output_height) {
    JSAMPROW rows[1] = {row};
    jpeg_read_scanlines(&cinfo, rows, 1);
  }
  if (row != nullptr) jpeg_finish_decompress(&cinfo);
  std::free(row);
  const bool warned = cinfo.err->num_warnings > 0;
  jpeg_destroy_decompress(&cinfo);
  return warned ? errors.message : "";
}

}  // namespace

std::string ImageSizeLimitError(int64_t width, int64_t height) {
  if (width > kMaxImageSide || height > kMaxImageSide ||
      width * height > kMaxImagePixels) {
    return "size " + std::to_string(width) + "x" + std::to_string(height) +
           " exceeds the limit (sides up to " + std::to_string(kMaxImageSide) +
           ", " + std::to_string(kMaxImagePixels) + " pixels)";
  }
  return "";
}

cv::Mat ReadImageFile(const std::filesystem::path& path, int flags) {
  const std::string bytes = ReadFileToString(path);
  return DecodeImageBytes(std::vector<uint8_t>(bytes.begin(), bytes.end()),
                          flags, path.string());
}

cv::Mat DecodeImageBytes(const std::vector<uint8_t>& data, int flags,
                         const std::string& where) {
  if (data.empty()) throw InputError(where + ": image file is empty");
  if (StartsWith(data, {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'})) {
    if (data.size() < kPngEnd.size() ||
        !std::equal(kPngEnd.begin(), kPngEnd.end(),
                    data.end() - kPngEnd.size())) {
      throw InputError(where + ": truncated PNG (no IEND chunk at the end)");
    }
  } else if (StartsWith(data, {0xFF, 0xD8, 0xFF})) {
    const size_t from =
        data.size() > kJpegTailBytes ? data.size() - kJpegTailBytes : 0;
    bool has_end = false;
    for (size_t i = data.size() - 1; i > from && !has_end; --i) {
      has_end = data[i - 1] == 0xFF && data[i] == 0xD9;
    }
    if (!has_end) {
      throw InputError(where + ": truncated JPEG (no end-of-image marker)");
    }
  }
  int64_t width = 0, height = 0;
  const bool is_jpeg = JpegSize(data, &width, &height);
  if (!is_jpeg && !PngSize(data, &width, &height) &&
      !PnmSize(data, &width, &height)) {
    // Other formats could claim any size, and OpenCV allocates it before
    // we could check (the image fuzzer's 47-byte file took 149 MB).
    throw InputError(where +
                     ": cannot decode image: not a PNG, JPEG or PNM file with "
                     "a readable size in its header");
  }
  const std::string error = ImageSizeLimitError(width, height);
  if (!error.empty()) throw InputError(where + ": image " + error);
  if (is_jpeg) {
    // An end marker appended to a truncated JPEG passes the check above;
    // libjpeg then only warns and fills the missing part with grey.
    const std::string problem = JpegDecodeProblem(data);
    if (!problem.empty()) {
      throw InputError(where + ": JPEG does not decode completely: " + problem);
    }
  }
  cv::Mat image;
  try {
    image = cv::imdecode(data, flags);
  } catch (const cv::Exception& e) {  // e.g. OpenCV's own pixel limit
    throw InputError(where + ": cannot decode image: " + e.err);
  }
  if (image.empty()) {
    throw InputError(where + ": cannot decode image");
  }
  return image;
}

}  // namespace monomap
