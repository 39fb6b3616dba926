// The bad-input catalogue (docs/reliability.md) of datasets and maps: each
// class of hostile or corrupt input, generated here, run through the
// `monomap` binary (tests/bad_input_catalogue.h says what each must give).
// The importers' inputs are in bad_import_test.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "monomap/io/map_format.h"
#include "monomap/sim/simulate.h"
#include "monomap/util/file.h"
#include "tests/bad_input_catalogue.h"
#include "tests/monomap_cli.h"

namespace monomap {
namespace {
namespace fs = std::filesystem;
using test::Case;
using test::RunMonomap;
using test::RunResult;

void Append(const fs::path& file, const std::string& text) {
  std::ofstream(file, std::ios::app) << text;
}

// Replaces the first line of `file` that starts with `prefix`.
void ReplaceLine(const fs::path& file, const std::string& prefix,
                 const std::string& line) {
  std::istringstream in(ReadFileToString(file));
  std::string out, l;
  bool done = false;
  while (std::getline(in, l)) {
    if (!done && l.rfind(prefix, 0) == 0) {
      l = line;
      done = true;
    }
    out += l + "\n";
  }
  ASSERT_TRUE(done) << file << " has no line starting with " << prefix;
  std::ofstream(file, std::ios::trunc) << out;
}

// The n-th data line (not a comment) of a text file.
std::string DataLine(const fs::path& file, int n) {
  std::istringstream in(ReadFileToString(file));
  std::string l;
  while (std::getline(in, l)) {
    if (l.empty() || l[0] == '#') continue;
    if (n-- == 0) return l;
  }
  return "";
}

// Moves the 4th odometry sample 50 m along x: a jump in one step.
void AddOdometryJump(const fs::path& dataset) {
  const fs::path file = dataset / "odometry.txt";
  const std::string line = DataLine(file, 3);
  std::istringstream in(line);
  double v[8];
  for (double& x : v) in >> x;
  ReplaceLine(file, line,
              std::to_string(v[0]) + " " + std::to_string(v[1] + 50) + " " +
                  std::to_string(v[2]) + " " + std::to_string(v[3]) +
                  " 0 0 0 1");
}

// Writes a PNG header that claims `width` x `height` into `file`.
void ClaimPngSize(const fs::path& file, uint32_t width, uint32_t height) {
  std::string png = ReadFileToString(file);
  for (int i = 0; i < 4; ++i) {
    png[16 + i] = static_cast<char>(width >> (24 - 8 * i));
    png[20 + i] = static_cast<char>(height >> (24 - 8 * i));
  }
  std::ofstream(file, std::ios::binary | std::ios::trunc) << png;
}

class BadInput : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = new fs::path(
        test::FolderWithDataset("monomap_bad_input", 12, 160, 120));
    WriteSmallMap(*root_ / "map");
  }
  static void TearDownTestSuite() {
    fs::remove_all(*root_);
    delete root_;
  }
  // A valid map with one textured plane, three points and one pose.
  static void WriteSmallMap(const fs::path& dir) {
    Map map;
    map.camera.width = 64;
    map.camera.height = 48;
    map.camera.fx = map.camera.fy = 50;
    map.camera.cx = 32;
    map.camera.cy = 24;
    TexturedPlane plane;
    plane.id = 0;
    plane.plane.normal = Eigen::Vector3d::UnitZ();
    plane.plane.offset = -2.0;
    plane.frame.origin = Eigen::Vector3d(-0.5, -0.5, 2.0);
    plane.pixels_per_meter = 64;
    plane.texture = cv::Mat(64, 64, CV_8UC4, cv::Scalar(90, 120, 150, 255));
    plane.polygon = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    map.planes.push_back(plane);
    for (int i = 0; i < 3; ++i) {
      Landmark l;
      l.id = i;
      l.x_in_world = Eigen::Vector3d(0.1 * i, 0, 2.0);
      l.plane_id = 0;
      map.landmarks.push_back(l);
    }
    map.trajectory.push_back({0.0, Rigid3d()});
    fs::create_directories(dir);
    WriteMap(dir, map);
  }

  static void RunCatalogue(const std::string& good, const std::string& command,
                           const std::vector<Case>& cases,
                           const std::string& out_extension = "") {
    test::RunCatalogue(*root_, good, command, cases, out_extension);
  }
  static fs::path* root_;
};
fs::path* BadInput::root_ = nullptr;

TEST_F(BadInput, Datasets) {
  const std::vector<Case> cases = {
      {"missing_image",
       [](const fs::path& d) { fs::remove(d / "rgb" / "000003.png"); },
       "rgb.txt:"},
      {"odometry_malformed",
       [](const fs::path& d) { Append(d / "odometry.txt", "99999 1 2 3\n"); },
       "odometry.txt:"},
      {"odometry_huge_translation",
       [](const fs::path& d) {
         Append(d / "odometry.txt", "99999 1e300 0 0 0 0 0 1\n");
       },
       "odometry.txt:"},
      {"odometry_jump", AddOdometryJump, "jump of"},
      {"odometry2d_huge_yaw",
       [](const fs::path& d) {
         Append(d / "odometry2d.txt", "99999 0 0 1e300\n");
       },
       "odometry2d.txt:"},
      {"camera_yaml_wrong_node_kind",
       [](const fs::path& d) {
         std::ofstream(d / "camera.yaml", std::ios::trunc)
             << "image_width: 160\nimage_height: 120\ncamera_matrix: 5\n";
       },
       "camera.yaml"},
      {"camera_mount_wrong_node_kind",
       [](const fs::path& d) {
         std::ofstream(d / "camera_mount.yaml", std::ios::trunc)
             << "base_from_cam: 5\n";
       },
       "camera_mount.yaml"},
      {"camera_yaml_huge",
       [](const fs::path& d) {
         ReplaceLine(d / "camera.yaml", "image_width:", "image_width: 100000");
         ReplaceLine(d / "camera.yaml",
                     "image_height:", "image_height: 100000");
       },
       "camera.yaml"},
      {"rgb_list_fifo",
       [](const fs::path& d) {
         fs::remove(d / "rgb.txt");
         mkfifo((d / "rgb.txt").c_str(), 0600);
       },
       "rgb.txt: is a FIFO"},
      {"rgb_list_symlink_loop",
       [](const fs::path& d) {
         fs::remove(d / "rgb.txt");
         fs::create_symlink("loop", d / "rgb.txt");
         fs::create_symlink("rgb.txt", d / "loop");
       },
       "rgb.txt: symbolic link loop"},
      {"rgb_list_long_line",
       [](const fs::path& d) {
         Append(d / "rgb.txt", std::string(2 << 20, '1') + "\n");
       },
       "rgb.txt:"},
      {"image_header_huge",
       [](const fs::path& d) {
         ClaimPngSize(d / "rgb" / "000002.png", 100000, 100000);
       },
       "000002.png"},
      {"image_truncated",
       [](const fs::path& d) {
         const fs::path f = d / "rgb" / "000004.png";
         const std::string png = ReadFileToString(f);
         std::ofstream(f, std::ios::binary | std::ios::trunc)
             << png.substr(0, png.size() / 2);
       },
       "000004.png"},
  };
  RunCatalogue("data", "build INPUT -o OUT --no-ba", cases);
}

TEST_F(BadInput, Maps) {
  auto set_json = [](const fs::path& d, const std::string& from,
                     const std::string& to) {
    std::string j = ReadFileToString(d / "map.json");
    ASSERT_NE(j.find(from), std::string::npos) << from;
    j.replace(j.find(from), from.size(), to);
    std::ofstream(d / "map.json", std::ios::trunc) << j;
  };
  const std::string ply_head = "ply\nformat ascii 1.0\n";
  const std::vector<Case> cases = {
      {"ply_huge_count_no_properties",
       [&](const fs::path& d) {
         std::ofstream(d / "points.ply", std::ios::trunc)
             << ply_head << "element junk 4000000000\nelement vertex 3\n"
             << "property float x\nproperty float y\nproperty float z\n"
             << "end_header\n0 0 2\n0.1 0 2\n0.2 0 2\n";
       },
       "points.ply"},
      {"ply_list_length_overflow",
       [&](const fs::path& d) {
         std::ofstream(d / "points.ply", std::ios::trunc)
             << ply_head << "element face 1\nproperty list uchar int i\n"
             << "element vertex 3\nproperty float x\nproperty float y\n"
             << "property float z\nend_header\n1e300 1\n0 0 2\n0.1 0 2\n"
             << "0.2 0 2\n";
       },
       "points.ply"},
      {"texture_header_huge",
       [](const fs::path& d) { ClaimPngSize(d / "plane_0.png", 30000, 30000); },
       "plane_0.png"},
      {"map_camera_huge",
       [&](const fs::path& d) {
         set_json(d, "\"width\": 64", "\"width\": 100000");
         set_json(d, "\"height\": 48", "\"height\": 100000");
       },
       "map.json: field 'camera'"},
      {"map_json_number_overflow",
       [&](const fs::path& d) { set_json(d, "\"fx\": 50.0", "\"fx\": 1e400"); },
       "map.json"},
      {"map_plane_id_negative",
       [&](const fs::path& d) { set_json(d, "\"id\": 0", "\"id\": -1"); },
       "planes[0].id"},
      {"map_json_symlink_loop",
       [](const fs::path& d) {
         fs::remove(d / "map.json");
         fs::create_symlink("map.json", d / "map.json");
       },
       "map.json"},
  };
  RunCatalogue("map", "render INPUT --pose \"0 0 0 0 0 0 1\" -o OUT", cases,
               ".png");
}

// The good inputs pass, so the catalogue measures the corruption only.
TEST_F(BadInput, TheUncorruptedInputsWork) {
  RunResult r = RunMonomap("render " + (*root_ / "map").string() +
                           " --pose \"0 0 0 0 0 0 1\" -o " +
                           (*root_ / "ok.png").string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(cv::imread((*root_ / "ok.png").string()).cols, 64);
  r = RunMonomap("build " + (*root_ / "data").string() + " -q --no-ba -o " +
                 (*root_ / "ok_map").string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
}

// With --drop-odometry-jumps a jump is dropped and reported, not fatal.
TEST_F(BadInput, OdometryJumpsCanBeDroppedAndReported) {
  const fs::path d = *root_ / "jump";
  fs::remove_all(d);
  fs::copy(*root_ / "data", d, fs::copy_options::recursive);
  AddOdometryJump(d);
  const fs::path out = *root_ / "jump_map";
  const RunResult r = RunMonomap("build " + d.string() + " -q --no-ba -o " +
                                 out.string() + " --drop-odometry-jumps");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("odometry.txt:"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("odometry jump dropped"), std::string::npos)
      << r.output;
  EXPECT_EQ(ReadMap(out).trajectory.size(), 12u);
}

}  // namespace
}  // namespace monomap
