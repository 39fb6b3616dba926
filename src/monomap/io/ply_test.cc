#include "monomap/io/ply.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <random>

#include "monomap/util/error.h"
#include "monomap/util/file.h"

namespace monomap {
namespace {
namespace fs = std::filesystem;

fs::path TempFile(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / "monomap_ply";
  fs::create_directories(dir);
  return dir / name;
}

void WriteBytes(const fs::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

template <typename T>
void Append(std::string* out, T value) {
  char buf[sizeof(T)];
  std::memcpy(buf, &value, sizeof(T));
  out->append(buf, sizeof(T));
}

std::string ErrorOf(const fs::path& path) {
  try {
    ReadPlyPoints(path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

std::vector<Landmark> RandomLandmarks(int n) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> x(-20, 20);
  std::uniform_int_distribution<int> c(0, 255);
  std::vector<Landmark> landmarks(n);
  for (int i = 0; i < n; ++i) {
    landmarks[i].id = 1000 + 3 * i;
    landmarks[i].x_in_world = {x(rng), x(rng), x(rng)};
    landmarks[i].color = Eigen::Vector3f(c(rng), c(rng), c(rng));
    landmarks[i].plane_id = i % 4 - 1;
    landmarks[i].num_observations = 3 + i % 200;
    landmarks[i].mean_reprojection_error_px = 0.01 * (i % 300);
    landmarks[i].triangulation_angle_deg = 0.37 * (i % 400);
  }
  return landmarks;
}

TEST(PlyTest, LandmarksRoundTrip) {
  const auto landmarks = RandomLandmarks(500);
  const fs::path path = TempFile("landmarks.ply");
  WriteLandmarksPly(path, landmarks);
  // 35 bytes per vertex after the header.
  const std::string data = ReadFileToString(path);
  EXPECT_EQ(data.size() - (data.find("end_header\n") + 11), 500u * 35u);

  const auto points = ReadPlyPoints(path);
  ASSERT_EQ(points.size(), landmarks.size());
  double max_error = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    max_error = std::max(
        max_error, (points[i] - landmarks[i].x_in_world).lpNorm<Eigen::Infinity>());
  }
  EXPECT_LT(max_error, 2e-6);  // float precision at |x| <= 20

  const auto read = ReadLandmarksPly(path);
  ASSERT_EQ(read.size(), landmarks.size());
  for (size_t i = 0; i < read.size(); ++i) {
    EXPECT_EQ(read[i].id, landmarks[i].id);
    EXPECT_EQ(read[i].plane_id, landmarks[i].plane_id);
    EXPECT_EQ(read[i].color, landmarks[i].color);
    EXPECT_EQ(read[i].num_observations, landmarks[i].num_observations);
    // Float precision.
    EXPECT_NEAR(read[i].mean_reprojection_error_px,
                landmarks[i].mean_reprojection_error_px, 1e-6);
    EXPECT_NEAR(read[i].triangulation_angle_deg,
                landmarks[i].triangulation_angle_deg, 2e-5);
  }

  WriteLandmarksPly(path, {});
  EXPECT_TRUE(ReadPlyPoints(path).empty());
}

// points.ply as written before the quality properties (23 bytes a vertex):
// still loads, quality left at zero.
TEST(PlyTest, ReadsLandmarksWithoutQualityProperties) {
  std::string ply =
      "ply\nformat binary_little_endian 1.0\n"
      "comment monomap landmarks (world frame, metres)\nelement vertex 2\n"
      "property float x\nproperty float y\nproperty float z\n"
      "property uchar red\nproperty uchar green\nproperty uchar blue\n"
      "property int feature_id\nproperty int plane\nend_header\n";
  for (int i = 0; i < 2; ++i) {
    Append<float>(&ply, 1.5f + i);
    Append<float>(&ply, -2.0f);
    Append<float>(&ply, 0.25f * i);
    for (uint8_t c : {10, 20, 30}) Append<uint8_t>(&ply, c + i);
    Append<int32_t>(&ply, 70 + i);
    Append<int32_t>(&ply, i - 1);
  }
  const fs::path path = TempFile("old_format.ply");
  WriteBytes(path, ply);
  const auto read = ReadLandmarksPly(path);
  ASSERT_EQ(read.size(), 2u);
  for (int i = 0; i < 2; ++i) {
    EXPECT_EQ(read[i].x_in_world, Eigen::Vector3d(1.5 + i, -2.0, 0.25 * i));
    EXPECT_EQ(read[i].color, Eigen::Vector3f(10 + i, 20 + i, 30 + i));
    EXPECT_EQ(read[i].id, 70 + i);
    EXPECT_EQ(read[i].plane_id, i - 1);
    EXPECT_EQ(read[i].num_observations, 0);
    EXPECT_EQ(read[i].mean_reprojection_error_px, 0.0);
    EXPECT_EQ(read[i].triangulation_angle_deg, 0.0);
  }
}

TEST(PlyTest, RejectsQualityOutOfRange) {
  const fs::path path = TempFile("quality.ply");
  const std::string head =
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\n"
      "property float y\nproperty float z\nproperty int track_length\n"
      "property float reprojection_error_px\n"
      "property float triangulation_angle_deg\nend_header\n1 2 3 4 0.5 2\n";
  const struct {
    const char* row;
    const char* field;
  } kBad[] = {{"1 2 3 -1 0.5 2\n", "'track_length'"},
              {"1 2 3 2.5 0.5 2\n", "'track_length'"},
              {"1 2 3 4 -0.5 2\n", "'reprojection_error_px'"},
              {"1 2 3 4 0.5 181\n", "'triangulation_angle_deg'"}};
  for (const auto& bad : kBad) {
    WriteBytes(path, head + bad.row);
    try {
      ReadLandmarksPly(path);
      ADD_FAILURE() << "expected InputError for " << bad.row;
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("quality.ply: vertex 1"), std::string::npos) << what;
      EXPECT_NE(what.find(bad.field), std::string::npos) << what;
    }
  }
  WriteBytes(path, head + "1 2 3 5 0.25 3.5\n");
  const auto read = ReadLandmarksPly(path);
  ASSERT_EQ(read.size(), 2u);
  EXPECT_EQ(read[1].num_observations, 5);
  EXPECT_EQ(read[1].mean_reprojection_error_px, 0.25);
  EXPECT_EQ(read[1].triangulation_angle_deg, 3.5);

  // The writer refuses what the reader would refuse.
  auto landmarks = RandomLandmarks(3);
  landmarks[1].mean_reprojection_error_px = std::nan("");
  EXPECT_THROW(WriteLandmarksPly(path, landmarks), OutputError);
  landmarks[1].mean_reprojection_error_px = 0.5;
  landmarks[2].triangulation_angle_deg = -1.0;
  EXPECT_THROW(WriteLandmarksPly(path, landmarks), OutputError);
}

TEST(PlyTest, ReadsAsciiWithOtherPropertiesAndElements) {
  const fs::path path = TempFile("ascii.ply");
  WriteBytes(path,
             "ply\r\nformat ascii 1.0\r\ncomment made by hand\r\n"
             "element camera 1\r\nproperty float focal\r\n"
             "element vertex 3\r\nproperty uchar red\r\nproperty double x\r\n"
             "property float nx\r\nproperty double y\r\nproperty double z\r\n"
             "property list uchar int ring\r\n"
             "element face 1\r\nproperty list uchar int vertex_indices\r\n"
             "end_header\r\n"
             "500.5\r\n"
             "255 1.25 0.1 -2.5 3e2 2 7 8\r\n"
             "0 -0.125 0 0.5 1e-3 0\r\n"
             "1 4 0 5 6 1 9\r\n"
             "3 0 1 2\r\n");
  const auto points = ReadPlyPoints(path);
  ASSERT_EQ(points.size(), 3u);
  EXPECT_EQ(points[0], Eigen::Vector3d(1.25, -2.5, 300));
  EXPECT_EQ(points[1], Eigen::Vector3d(-0.125, 0.5, 1e-3));
  EXPECT_EQ(points[2], Eigen::Vector3d(4, 5, 6));

  // A short row is truncation, a bad token is named.
  WriteBytes(path,
             "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\n"
             "property float y\nproperty float z\nend_header\n1 2 3\n4 5\n");
  EXPECT_NE(ErrorOf(path).find("truncated"), std::string::npos);
  WriteBytes(path,
             "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
             "property float y\nproperty float z\nend_header\n1 2 z3\n");
  EXPECT_NE(ErrorOf(path).find("'z3'"), std::string::npos);
}

TEST(PlyTest, ReadsBinaryDoublesAndSkipsOtherTypes) {
  std::string ply =
      "ply\nformat binary_little_endian 1.0\n"
      "element header_info 2\nproperty list uchar short ids\n"
      "element vertex 2\nproperty short s\nproperty double x\n"
      "property double y\nproperty uint u\nproperty double z\n"
      "property char c\nend_header\n";
  Append<uint8_t>(&ply, 2);
  Append<int16_t>(&ply, 1);
  Append<int16_t>(&ply, 2);
  Append<uint8_t>(&ply, 0);
  const double values[2][3] = {{0.1, -7e5, 3.0 / 7.0}, {1e-9, 2, -3}};
  for (const auto& v : values) {
    Append<int16_t>(&ply, -4);
    Append<double>(&ply, v[0]);
    Append<double>(&ply, v[1]);
    Append<uint32_t>(&ply, 99);
    Append<double>(&ply, v[2]);
    Append<int8_t>(&ply, -1);
  }
  const fs::path path = TempFile("binary.ply");
  WriteBytes(path, ply);
  const auto points = ReadPlyPoints(path);
  ASSERT_EQ(points.size(), 2u);
  for (int i = 0; i < 2; ++i) {
    EXPECT_EQ(points[i], Eigen::Vector3d(values[i][0], values[i][1],
                                         values[i][2]));  // exact doubles
  }
  // One byte short.
  WriteBytes(path, ply.substr(0, ply.size() - 1));
  EXPECT_NE(ErrorOf(path).find("truncated"), std::string::npos);
}

TEST(PlyTest, RejectsTruncatedAndMalformedFiles) {
  const fs::path path = TempFile("bad.ply");
  WriteLandmarksPly(path, RandomLandmarks(10));
  const std::string good = ReadFileToString(path);

  WriteBytes(path, good.substr(0, good.size() - 5));
  std::string error = ErrorOf(path);
  EXPECT_NE(error.find("bad.ply"), std::string::npos) << error;
  EXPECT_NE(error.find("truncated"), std::string::npos) << error;

  WriteBytes(path, good.substr(0, good.find("end_header")));
  EXPECT_NE(ErrorOf(path).find("no 'end_header'"), std::string::npos);

  std::string big_endian = good;
  big_endian.replace(big_endian.find("binary_little_endian"), 20,
                     "binary_big_endian");
  WriteBytes(path, big_endian);
  EXPECT_NE(ErrorOf(path).find("unsupported PLY format"), std::string::npos);

  WriteBytes(path, "PLY\n");
  EXPECT_NE(ErrorOf(path).find("not a PLY file"), std::string::npos);

  WriteBytes(path,
             "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
             "property float y\nend_header\n1 2\n");
  EXPECT_NE(ErrorOf(path).find("no property 'z'"), std::string::npos);

  WriteBytes(path,
             "ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\n"
             "end_header\n1\n");
  EXPECT_NE(ErrorOf(path).find("bad.ply:4:"), std::string::npos);

  WriteBytes(path,
             "ply\nformat binary_little_endian 1.0\n"
             "element vertex 99999999999\nproperty float x\nproperty float y\n"
             "property float z\nend_header\n");
  EXPECT_NE(ErrorOf(path).find("truncated"), std::string::npos);

  EXPECT_NE(ErrorOf(TempFile("missing.ply")).find("missing.ply"),
            std::string::npos);
}

// Counts a small file cannot hold are refused before any loop: these took
// billions of iterations (or an undefined cast) before.
TEST(PlyTest, CountsAreBoundedByTheFileSize) {
  const fs::path path = TempFile("counts.ply");
  // An element with a huge count and no properties, before the vertices.
  WriteBytes(path,
             "ply\nformat ascii 1.0\nelement junk 4000000000\n"
             "element vertex 1\nproperty float x\nproperty float y\n"
             "property float z\nend_header\n1 2 3\n");
  std::string error = ErrorOf(path);
  EXPECT_NE(error.find("counts.ply"), std::string::npos) << error;
  EXPECT_NE(error.find("'junk'"), std::string::npos) << error;
  EXPECT_NE(error.find("no properties"), std::string::npos) << error;

  // ASCII: more rows than the data can hold.
  WriteBytes(path,
             "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
             "property float y\nproperty float z\nend_header\n1 2 3\n4 5 6\n");
  EXPECT_NE(ErrorOf(path).find("count 3 needs"), std::string::npos);
  // ... while exactly enough data (no final newline) is fine.
  WriteBytes(path,
             "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\n"
             "property float y\nproperty float z\nend_header\n1 2 3 4 5 6");
  EXPECT_EQ(ReadPlyPoints(path).size(), 2u);

  // A list length far beyond any integer, in ASCII.
  WriteBytes(path,
             "ply\nformat ascii 1.0\nelement face 1\n"
             "property list uchar int idx\nelement vertex 1\n"
             "property float x\nproperty float y\nproperty float z\n"
             "end_header\n1e300 1\n1 2 3\n");
  error = ErrorOf(path);
  EXPECT_NE(error.find("list length"), std::string::npos) << error;
  EXPECT_NE(error.find("'face' row 0"), std::string::npos) << error;

  // Ids out of the range of their types.
  WriteBytes(path,
             "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
             "property float y\nproperty float z\nproperty int plane\n"
             "end_header\n1 2 3 1e300\n");
  try {
    ReadLandmarksPly(path);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'plane'"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace monomap
