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

  EXPECT_NE(Error(Write(".png", 0)).find("empty"), std::string::npos);
  EXPECT_NE(Error(dir_ / "missing.png").find("cannot open"), std::string::npos);
  // Not an image at all.
  const fs::path text = dir_ / "text.png";
  std::ofstream(text) << "not an image\n";
  EXPECT_NE(Error(text).find("cannot decode"), std::string::npos);
}

}  // namespace
}  // namespace monomap
