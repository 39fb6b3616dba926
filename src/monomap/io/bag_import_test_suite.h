// The import tests every bag format passes, written once: a
// type-parameterized gtest suite that rosbag_import_test.cc (ROS 1) and
// rosbag2_import_test.cc (ROS 2) instantiate with their Format:
//   static constexpr const char* kName;   // for the scratch directory
//   static std::filesystem::path Write(const std::filesystem::path& dir,
//                                      const std::string& name,
//                                      const bag_test::BagSpec& spec);
//   static RosbagImportReport Import(const std::filesystem::path& bag,
//                                    const std::filesystem::path& out,
//                                    const RosbagImportOptions& options);
// What only one format has (its topic type names, truncated files, ROS 2's
// storage plugins) stays in that format's test file.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "monomap/io/bag_test_sequence.h"

namespace monomap::bag_test {

template <typename Format>
class BagImportTest : public ::testing::Test {
 protected:
  // A scratch directory per process and test (other checkouts may run the
  // same tests at the same time), removed after the test.
  void SetUp() override {
    const ::testing::TestInfo* info =
        ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = std::filesystem::temp_directory_path() /
           (std::string("monomap_bag_import_") + Format::kName + "_" +
            std::to_string(getpid()) + "_" + info->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }

  std::filesystem::path Write(const std::string& name, const BagSpec& spec) {
    return Format::Write(dir_, name, spec);
  }
  // Imports a bag of `spec` and checks everything the importer promises.
  void CheckImport(const BagSpec& spec) {
    const std::filesystem::path bag = Write("drive", spec);
    const std::filesystem::path out = dir_ / "dataset";
    CheckImportedDrive(spec, Format::Import(bag, out, Options(spec)), out);
  }
  // The import's InputError for `spec`, which must start with the bag's
  // file name and contain `message`.
  void ExpectError(const std::string& name, const BagSpec& spec,
                   const std::string& message) {
    const std::filesystem::path bag = Write(name, spec);
    const std::string e =
        ImportError(&Format::Import, bag, dir_ / "kept", Options(spec));
    EXPECT_NE(e.find(bag.filename().string() + ": " + message),
              std::string::npos)
        << e;
  }

  std::filesystem::path dir_;
};

TYPED_TEST_SUITE_P(BagImportTest);

TYPED_TEST_P(BagImportTest, Mono8WithOdometryTopic) { this->CheckImport({}); }

TYPED_TEST_P(BagImportTest, Rgb8WithTfOdometry) {
  BagSpec spec;
  spec.encoding = "rgb8";
  spec.odom_as_tf = true;
  this->CheckImport(spec);
}

TYPED_TEST_P(BagImportTest, Bgr8WithEquidistantCameraInfo) {
  BagSpec spec;
  spec.encoding = "bgr8";
  spec.fisheye = true;
  this->CheckImport(spec);
}

TYPED_TEST_P(BagImportTest, CompressedPngAndJpeg) {
  BagSpec spec;
  spec.encoding = "png";
  this->CheckImport(spec);
  spec.encoding = "jpeg";
  this->CheckImport(spec);
}

TYPED_TEST_P(BagImportTest, BadEncodingCalibrationAndLensNameTheField) {
  BagSpec spec;
  spec.encoding = "bgra8";
  this->ExpectError("enc", spec,
                    "topic '/cam/image_raw': field 'encoding': 'bgra8' is "
                    "not supported");
  spec = {};
  spec.calibrated = false;
  this->ExpectError("uncal", spec,
                    "topic '/cam/camera_info': field 'K': no calibration");
  spec = {};
  spec.distortion_model = "rational_polynomial";
  this->ExpectError("rational", spec,
                    "topic '/cam/camera_info': field 'distortion_model': "
                    "'rational_polynomial' is not supported");
  spec = {};
  spec.distortion_model = "equidistant";  // with plumb_bob's 5 numbers
  this->ExpectError("five", spec,
                    "topic '/cam/camera_info': field 'D': equidistant needs "
                    "4 coefficients, got 5");
}

TYPED_TEST_P(BagImportTest, MissingMountIsAnErrorUnlessAFileGivesIt) {
  BagSpec spec;
  spec.with_tf_static = false;
  CheckMissingMount(&TypeParam::Import, this->Write("nomount", spec),
                    this->dir_);
}

REGISTER_TYPED_TEST_SUITE_P(BagImportTest, Mono8WithOdometryTopic,
                            Rgb8WithTfOdometry, Bgr8WithEquidistantCameraInfo,
                            CompressedPngAndJpeg,
                            BadEncodingCalibrationAndLensNameTheField,
                            MissingMountIsAnErrorUnlessAFileGivesIt);

}  // namespace monomap::bag_test
