#include "monomap/io/image_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "monomap/util/error.h"

namespace monomap {
namespace {

namespace fs = std::filesystem;

class ImageFileTest : public ::testing::Test {
 protected:
  ImageFileTest()
      : dir_(fs::temp_directory_path() /
             ("monomap_image_file_test_" + std::to_string(::getpid()))) {
    fs::create_directories(dir_);
    image_.create(48, 64, CV_8UC1);
    cv::randu(image_, 0, 255);
  }
  ~ImageFileTest() override { fs::remove_all(dir_); }

  // Writes the encoding of image_ as `ext`, cut to `keep` bytes (-1: all)
  // and followed by `tail`.
  fs::path Write(const std::string& ext, long keep = -1,
                 const std::vector<uint8_t>& tail = {}) {
    std::vector<uint8_t> data;
    EXPECT_TRUE(cv::imencode(ext, image_, data));
    if (keep >= 0) data.resize(static_cast<size_t>(keep));
    data.insert(data.end(), tail.begin(), tail.end());
    const fs::path path = dir_ / ("image_" + std::to_string(count_++) + ext);
    std::ofstream(path, std::ios::binary)
        .write(reinterpret_cast<const char*>(data.data()),
               static_cast<std::streamsize>(data.size()));
    return path;
  }

  // The InputError's message, or "" if none was thrown.
  static std::string Error(const fs::path& path) {
    try {
      ReadImageFile(path, cv::IMREAD_GRAYSCALE);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  }

  fs::path dir_;
  cv::Mat image_;
  int count_ = 0;
};

TEST_F(ImageFileTest, WholeFilesDecode) {
  for (const std::string ext : {".png", ".jpg", ".pgm"}) {
    const cv::Mat read = ReadImageFile(Write(ext), cv::IMREAD_GRAYSCALE);
    ASSERT_EQ(read.size(), image_.size()) << ext;
    if (ext != ".jpg") {
      EXPECT_EQ(cv::norm(read, image_, cv::NORM_INF), 0);
    }
  }
  // Padding after a JPEG's end marker is allowed.
  EXPECT_EQ(Error(Write(".jpg", -1, std::vector<uint8_t>(100, 0))), "");
}

TEST_F(ImageFileTest, TruncatedFilesAreNamed) {
  std::vector<uint8_t> png, jpg;
  cv::imencode(".png", image_, png);
  cv::imencode(".jpg", image_, jpg);
  // OpenCV itself returns a grey-filled image for a JPEG cut in half.
  const fs::path half_jpg = Write(".jpg", static_cast<long>(jpg.size() / 2));
  EXPECT_FALSE(cv::imread(half_jpg.string(), cv::IMREAD_GRAYSCALE).empty());
  std::string e = Error(half_jpg);
  EXPECT_NE(e.find(half_jpg.string()), std::string::npos) << e;
  EXPECT_NE(e.find("truncated JPEG"), std::string::npos) << e;

  const fs::path cut_png = Write(".png", static_cast<long>(png.size() - 5));
  e = Error(cut_png);
  EXPECT_NE(e.find(cut_png.string()), std::string::npos) << e;
  EXPECT_NE(e.find("truncated PNG"), std::string::npos) << e;

  // Cut in half with an end marker appended: libjpeg alone would only warn
  // ("premature end") and fill the rest with grey.
  const fs::path patched =
      Write(".jpg", static_cast<long>(jpg.size() / 2), {0xFF, 0xD9});
  EXPECT_FALSE(cv::imread(patched.string(), cv::IMREAD_GRAYSCALE).empty());
  e = Error(patched);
  EXPECT_NE(e.find(patched.string()), std::string::npos) << e;
  EXPECT_NE(e.find("does not decode completely"), std::string::npos) << e;
  EXPECT_NE(e.find("premature end"), std::string::npos) << e;

  EXPECT_NE(Error(Write(".png", 0)).find("empty"), std::string::npos);
  EXPECT_NE(Error(dir_ / "missing.png").find("not found"), std::string::npos);
  // Not an image at all.
  const fs::path text = dir_ / "text.png";
  std::ofstream(text) << "not an image\n";
  EXPECT_NE(Error(text).find("cannot decode"), std::string::npos);
}

// Found by image_fuzzer (fuzz/corpus/image/other_format_timeout): 47 bytes
// that OpenCV took for a format other than PNG or JPEG, whose size was not
// checked; decoding allocated 149 MB and ran over 10 s under ASan. Formats
// without a size check are refused, PNM's header is read.
TEST_F(ImageFileTest, FormatsWithoutASizeCheckAreRefused) {
  const std::vector<uint8_t> finding = {
      0x2f, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x61, 0x45, 0x74, 0x35,
      0x15, 0xff, 0x43, 0xc4, 0x01, 0x93, 0xce, 0xd2, 0x34, 0xe8, 0x17, 0x53,
      0x74, 0x35, 0x63, 0x74, 0x79, 0x70, 0x65, 0x49, 0x63, 0x45, 0xcd, 0x00,
      0x00, 0x00, 0x00, 0x49, 0x45, 0x4e, 0x44, 0xae, 0x42, 0x60, 0x82};
  std::string e;
  try {
    DecodeImageBytes(finding, cv::IMREAD_COLOR, "finding");
  } catch (const InputError& error) {
    e = error.what();
  }
  EXPECT_NE(e.find("finding: cannot decode image: not a PNG, JPEG or PNM"),
            std::string::npos)
      << e;
  e = Error(Write(".bmp"));
  EXPECT_NE(e.find("not a PNG, JPEG or PNM"), std::string::npos) << e;
  // A PNM header claiming 100000 x 100000 (with a comment line).
  const std::string pgm =
      "P5\n# big\n100000 100000\n255\n" + std::string(64, 'x');
  e.clear();
  try {
    DecodeImageBytes(std::vector<uint8_t>(pgm.begin(), pgm.end()),
                     cv::IMREAD_GRAYSCALE, "big.pgm");
  } catch (const InputError& error) {
    e = error.what();
  }
  EXPECT_NE(e.find("big.pgm: image size 100000x100000 exceeds the limit"),
            std::string::npos)
      << e;
}

// Sizes are checked in the header, before anything is decoded.
TEST_F(ImageFileTest, HugeHeadersAreRefusedBeforeDecoding) {
  std::vector<uint8_t> png;
  cv::imencode(".png", image_, png);
  for (int i = 0; i < 4; ++i) {
    png[16 + i] = static_cast<uint8_t>(30000u >> (24 - 8 * i));
    png[20 + i] = static_cast<uint8_t>(30000u >> (24 - 8 * i));
  }
  const fs::path path = dir_ / "huge.png";
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(png.data()),
             static_cast<std::streamsize>(png.size()));
  std::string e = Error(path);
  EXPECT_NE(e.find("huge.png: image size 30000x30000 exceeds the limit"),
            std::string::npos)
      << e;
  // JPEG: the height and width of the start-of-frame marker.
  std::vector<uint8_t> jpg;
  cv::imencode(".jpg", image_, jpg);
  for (size_t i = 2; i + 8 < jpg.size();
       i += 2 + (jpg[i + 2] << 8 | jpg[i + 3])) {
    if (jpg[i + 1] == 0xC0) {
      jpg[i + 5] = jpg[i + 7] = 0xEA;  // 60000
      jpg[i + 6] = jpg[i + 8] = 0x60;
      break;
    }
  }
  const fs::path jpath = dir_ / "huge.jpg";
  std::ofstream(jpath, std::ios::binary)
      .write(reinterpret_cast<const char*>(jpg.data()),
             static_cast<std::streamsize>(jpg.size()));
  e = Error(jpath);
  EXPECT_NE(e.find("image size 60000x60000 exceeds"), std::string::npos) << e;
  EXPECT_EQ(ImageSizeLimitError(kMaxImageSide, kMaxImagePixels / kMaxImageSide),
            "");
  EXPECT_NE(ImageSizeLimitError(kMaxImageSide + 1, 1), "");
}

}  // namespace
}  // namespace monomap
