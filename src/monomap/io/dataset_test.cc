#include "monomap/io/dataset.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "monomap/io/trajectory_io.h"
#include "monomap/util/error.h"

namespace monomap {
namespace {
namespace fs = std::filesystem;

// Writes a 3-frame dataset; `odometry` replaces odometry.txt if non-empty.
// Removes the test datasets when the test program ends.
struct TempDirs {
  std::vector<fs::path> dirs;
  ~TempDirs() {
    std::error_code ec;
    for (const fs::path& d : dirs) fs::remove_all(d, ec);
  }
};
TempDirs temp_dirs;

fs::path MakeDataset(const std::string& name, const std::string& odometry = "",
                     int image_width = 64) {
  // Per process: other checkouts may run the same test at the same time.
  const fs::path dir = fs::temp_directory_path() /
                       ("monomap_io_" + name + "_" + std::to_string(getpid()));
  fs::remove_all(dir);
  temp_dirs.dirs.push_back(dir);
  fs::create_directories(dir / "rgb");
  Camera c;
  c.width = 64;
  c.height = 48;
  c.fx = c.fy = 50;
  c.cx = 31.5;
  c.cy = 23.5;
  c.distortion = {-0.1, 0.01, 0, 0, 0};
  WriteCameraYaml(dir / "camera.yaml", c, "test");
  std::ofstream rgb(dir / "rgb.txt");
  rgb << "# timestamp filename\n";
  for (int i = 0; i < 3; ++i) {
    const std::string file = "rgb/" + std::to_string(i) + ".png";
    cv::imwrite((dir / file).string(),
                cv::Mat(48, image_width, CV_8UC1, cv::Scalar(i * 10)));
    rgb << 0.1 * (i + 1) << " " << file << "\n";
  }
  std::ofstream odo(dir / "odometry.txt");
  if (odometry.empty()) {
    odo << "# odometry\n0.05 0 0 0 0 0 0 1\n0.25 1 0 0 0 0 0 1\n"
           "0.35 2 0 0 0 0 0 1\n";
  } else {
    odo << odometry;
  }
  return dir;
}

TEST(Dataset, LoadsAndInterpolatesOdometry) {
  const Dataset ds = LoadDataset(MakeDataset("ok"));
  ASSERT_EQ(ds.frames.size(), 3u);
  EXPECT_EQ(ds.camera.width, 64);
  EXPECT_NEAR(ds.camera.distortion[0], -0.1, 1e-12);
  // Frame at t=0.1 lies a quarter of the way from t=0.05 to t=0.25.
  EXPECT_NEAR(ds.frames[0].odometry_world_from_cam.translation.x(), 0.25,
              1e-9);
  EXPECT_NEAR(ds.frames[2].odometry_world_from_cam.translation.x(), 1.5,
              1e-9);
  EXPECT_EQ(ds.LoadImage(1).at<uint8_t>(0, 0), 10);
}

void ExpectInputError(const fs::path& dir, const std::string& needle) {
  try {
    LoadDataset(dir);
    FAIL() << "expected InputError containing " << needle;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos)
        << e.what();
  }
}

TEST(Dataset, MalformedOdometryNamesFileAndLine) {
  ExpectInputError(MakeDataset("bad_line", "0.05 0 0 0 0 0 0 1\n0.2 1 2\n"),
                   "odometry.txt:2");
  ExpectInputError(
      MakeDataset("nan", "0.05 0 0 0 0 0 0 1\n0.3 nan 0 0 0 0 0 1\n"),
      "odometry.txt:2");
  ExpectInputError(
      MakeDataset("order", "0.05 0 0 0 0 0 0 1\n0.05 0 0 0 0 0 0 1\n"),
      "does not increase");
}

TEST(Dataset, FramesWithoutOdometryAreRefused) {
  // Odometry ends before the last frame.
  ExpectInputError(
      MakeDataset("gap", "0.05 0 0 0 0 0 0 1\n0.25 1 0 0 0 0 0 1\n"),
      "rgb.txt:4: no odometry");
}

TEST(Dataset, WrongImageSizeIsNamed) {
  const Dataset ds = LoadDataset(MakeDataset("size", "", 60));
  try {
    ds.LoadImage(0);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("0.png: image is 60x48"),
              std::string::npos)
        << e.what();
  }
}

TEST(Dataset, TruncatedImageIsNamed) {
  const fs::path dir = MakeDataset("truncated");
  fs::resize_file(dir / "rgb" / "1.png",
                  fs::file_size(dir / "rgb" / "1.png") / 2);
  const Dataset ds = LoadDataset(dir);
  EXPECT_EQ(ds.LoadImage(0).cols, 64);
  try {
    ds.LoadImage(1);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("1.png: truncated PNG"),
              std::string::npos)
        << e.what();
  }
}

TEST(Dataset, MalformedCameraYamlNamesField) {
  const fs::path dir = MakeDataset("yaml");
  std::ofstream(dir / "camera.yaml") << "image_width: 64\nimage_height: 48\n"
                                        "camera_matrix: {data: [1, 2]}\n";
  ExpectInputError(dir, "camera_matrix.data");
  std::ofstream(dir / "camera.yaml") << "image_width: [64\n";
  ExpectInputError(dir, "camera.yaml:");
}

TEST(Trajectory, RoundTrip) {
  std::vector<TimedPose> poses = {
      {0.5, Rigid3d(YawRotation(0.3), Eigen::Vector3d(1, 2, 3))},
      {0.6, Rigid3d(YawRotation(-0.3), Eigen::Vector3d(-1, 2, 3))}};
  const fs::path path = fs::temp_directory_path() / "monomap_traj.txt";
  WriteTumTrajectory(path, poses);
  const auto back = ReadTumTrajectory(path);
  ASSERT_EQ(back.size(), 2u);
  EXPECT_NEAR(back[1].timestamp, 0.6, 1e-9);
  EXPECT_LT((back[1].world_from_cam.translation -
             poses[1].world_from_cam.translation).norm(), 1e-8);
  EXPECT_LT(AngleBetween(back[0].world_from_cam.rotation,
                         poses[0].world_from_cam.rotation), 1e-7);
}

}  // namespace
}  // namespace monomap
