#include "monomap/io/colmap_export.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <regex>

#include "monomap/util/error.h"
#include "monomap/util/file.h"
#include "monomap/util/random.h"

namespace monomap {
namespace {

namespace fs = std::filesystem;

fs::path TempDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("monomap_colmap_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// A camera driving along x past a wall of points at y = 3, looking at it
// (camera z along world +y), with noise-free or noisy observations.
struct Scene {
  Map map;
  std::vector<Track> tracks;
};

Scene MakeScene(const std::array<double, 5>& distortion, double noise_px) {
  Scene s;
  s.map.camera = {640, 480, 500.0, 505.0, 319.2, 241.7, distortion};
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, noise_px);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  // cam x = world x, cam y = world -z, cam z = world y.
  Eigen::Matrix3d r;
  r << 1, 0, 0, 0, 0, 1, 0, -1, 0;
  const int num_frames = 12;
  for (int f = 0; f < num_frames; ++f) {
    const Eigen::Quaterniond q(r);
    const Eigen::Quaterniond wobble(
        Eigen::AngleAxisd(0.02 * f, Eigen::Vector3d(0.3, 1, 0.2).normalized()));
    s.map.trajectory.push_back(
        {0.1 * f,
         Rigid3d(wobble * q, Eigen::Vector3d(0.2 * f, 0.05 * f, 1.0))});
  }
  for (int i = 0; i < 60; ++i) {
    Landmark l;
    l.id = 3 * i + 5;  // ids need not be contiguous
    l.x_in_world = {1.2 + 1.5 * uni(rng), 3.0 + 0.3 * uni(rng),
                    1.0 + 0.8 * uni(rng)};
    l.color = Eigen::Vector3f(10.f * (i % 25), 100.f, 255.f - i);
    Track t;
    t.id = l.id;
    for (int f = i % 4; f < num_frames; ++f) {
      const Rigid3d cam_from_world =
          s.map.trajectory[f].world_from_cam.Inverse();
      const Eigen::Vector2d px =
          s.map.camera.ImageFromCam(cam_from_world * l.x_in_world);
      if (!s.map.camera.InImage(px)) continue;
      t.observations.push_back(
          {f, px + DrawLastFirst<Eigen::Vector2d>(noise, rng)});
    }
    s.map.landmarks.push_back(l);
    s.tracks.push_back(t);
  }
  // A track without a landmark and an observation of a frame the map does
  // not have.
  s.tracks.push_back({999, {{0, {10.0, 10.0}}}});
  s.tracks[0].observations.push_back({num_frames + 3, {5.0, 5.0}});
  return s;
}

// Reprojection with the COLMAP camera and pose as stored, done here by hand
// (COLMAP's OPENCV / FULL_OPENCV polynomial), independent of monomap's
// Camera: checks the pose direction and the half-pixel shift.
Eigen::Vector2d ColmapProject(const ColmapModel::Camera& c,
                              const ColmapModel::Image& im,
                              const Eigen::Vector3d& x) {
  const Eigen::Vector3d xc =
      im.cam_from_world_rotation * x + im.cam_from_world_translation;
  const double u = xc.x() / xc.z(), v = xc.y() / xc.z();
  std::vector<double> p = c.params;
  p.resize(12, 0.0);
  const double r2 = u * u + v * v;
  const double radial = 1 + p[4] * r2 + p[5] * r2 * r2 + p[8] * r2 * r2 * r2;
  const double ud = u * radial + 2 * p[6] * u * v + p[7] * (r2 + 2 * u * u);
  const double vd = v * radial + p[6] * (r2 + 2 * v * v) + 2 * p[7] * u * v;
  return {p[0] * ud + p[2], p[1] * vd + p[3]};
}

TEST(ColmapExportTest, CameraModelFollowsDistortion) {
  Camera cam{640, 480, 500, 500, 320, 240, {0, 0, 0, 0, 0}};
  EXPECT_EQ(ColmapCameraFromCamera(cam).model, "PINHOLE");
  EXPECT_DOUBLE_EQ(ColmapCameraFromCamera(cam).params[2], 320.5);
  cam.distortion = {-0.2, 0.05, 0.001, -0.002, 0.0};
  EXPECT_EQ(ColmapCameraFromCamera(cam).model, "OPENCV");
  cam.distortion[4] = 0.01;
  const ColmapModel::Camera full = ColmapCameraFromCamera(cam);
  EXPECT_EQ(full.model, "FULL_OPENCV");
  const Camera back = CameraFromColmapCamera(full);
  EXPECT_DOUBLE_EQ(back.cx, 320.0);
  EXPECT_EQ(back.distortion, cam.distortion);
  Camera lens = cam;
  lens.model = LensModel::kEquidistant;
  lens.distortion = {0.02, -0.004, 0.001, -0.0002, 0.0};
  const ColmapModel::Camera fisheye = ColmapCameraFromCamera(lens);
  EXPECT_EQ(fisheye.model, "OPENCV_FISHEYE");
  ASSERT_EQ(fisheye.params.size(), 8u);
  EXPECT_EQ(fisheye.params[7], -0.0002);
  const Camera fisheye_back = CameraFromColmapCamera(fisheye);
  EXPECT_EQ(fisheye_back.model, LensModel::kEquidistant);
  EXPECT_EQ(fisheye_back.distortion, lens.distortion);
  ColmapModel::Camera thin_prism = full;
  thin_prism.model = "THIN_PRISM_FISHEYE";
  EXPECT_THROW(CameraFromColmapCamera(thin_prism), InputError);
  ColmapModel::Camera rational = full;
  rational.params[9] = 0.1;
  EXPECT_THROW(CameraFromColmapCamera(rational), InputError);
}

TEST(ColmapExportTest, RoundTripKeepsPosesPointsAndTracks) {
  for (const auto& distortion :
       {std::array<double, 5>{0, 0, 0, 0, 0},
        std::array<double, 5>{-0.25, 0.08, 0.001, -0.0005, 0.0},
        std::array<double, 5>{-0.25, 0.08, 0.001, -0.0005, -0.02}}) {
    const Scene s = MakeScene(distortion, 0.0);
    ColmapExportReport report;
    const ColmapModel model = MakeColmapModel(s.map, s.tracks, {}, &report);
    const fs::path dir = TempDir("roundtrip");
    WriteColmapText(dir, model);
    const ColmapModel back = ReadColmapText(dir);

    ASSERT_EQ(back.cameras.size(), 1u);
    const Camera cam = CameraFromColmapCamera(back.cameras[0]);
    EXPECT_EQ(cam.distortion, s.map.camera.distortion);
    EXPECT_NEAR(cam.cx, s.map.camera.cx, 1e-12);
    ASSERT_EQ(back.images.size(), s.map.trajectory.size());
    EXPECT_EQ(report.num_dropped_observations, 1);  // the frame out of range
    size_t observations = 0;
    double max_pose_error = 0, max_reprojection_px = 0;
    for (size_t f = 0; f < back.images.size(); ++f) {
      const ColmapModel::Image& im = back.images[f];
      EXPECT_EQ(im.name, model.images[f].name);
      const Rigid3d world_from_cam =
          Rigid3d(im.cam_from_world_rotation, im.cam_from_world_translation)
              .Inverse();
      max_pose_error =
          std::max({max_pose_error,
                    (world_from_cam.translation -
                     s.map.trajectory[f].world_from_cam.translation)
                        .norm(),
                    world_from_cam.rotation.angularDistance(
                        s.map.trajectory[f].world_from_cam.rotation)});
      observations += im.points2d.size();
    }
    EXPECT_LT(max_pose_error, 1e-12);
    ASSERT_EQ(back.points.size(), s.map.landmarks.size());
    size_t track_elements = 0;
    for (size_t i = 0; i < back.points.size(); ++i) {
      const ColmapModel::Point3D& p = back.points[i];
      EXPECT_EQ(p.id, s.map.landmarks[i].id);
      EXPECT_EQ(p.xyz, s.map.landmarks[i].x_in_world);
      EXPECT_LT(p.error, 1e-6);  // noise-free observations
      track_elements += p.track.size();
      for (const auto& e : p.track) {
        const ColmapModel::Image& im = back.images[e.image_id - 1];
        const Eigen::Vector2d predicted =
            ColmapProject(back.cameras[0], im, p.xyz);
        max_reprojection_px =
            std::max(max_reprojection_px,
                     (predicted - im.points2d[e.point2d_idx].xy).norm());
      }
    }
    EXPECT_EQ(track_elements, observations);
    EXPECT_EQ(static_cast<int>(observations), report.num_observations);
    EXPECT_GT(report.num_observations, 300);
    EXPECT_LT(max_reprojection_px, 1e-6);
  }
}

TEST(ColmapExportTest, ErrorFieldIsTheReprojectionErrorOfNoisyTracks) {
  const Scene s = MakeScene({-0.25, 0.08, 0.001, -0.0005, 0.0}, 0.5);
  ColmapExportReport report;
  MakeColmapModel(s.map, s.tracks, {}, &report);
  // 2D Gaussian noise of 0.5 px per axis: mean norm 0.5 * sqrt(pi / 2).
  EXPECT_NEAR(report.mean_reprojection_error_px, 0.627, 0.06);
  EXPECT_EQ(report.num_points_with_track, 60);
}

TEST(ColmapExportTest, WithoutTracksExportsPosesAndPoints) {
  const Scene s = MakeScene({0, 0, 0, 0, 0}, 0.0);
  ColmapExportReport report;
  const ColmapModel model = MakeColmapModel(s.map, {}, {}, &report);
  const fs::path dir = TempDir("notracks");
  WriteColmapText(dir, model);
  const ColmapModel back = ReadColmapText(dir);
  EXPECT_EQ(back.images.size(), 12u);
  EXPECT_EQ(back.points.size(), 60u);
  EXPECT_EQ(report.num_observations, 0);
  for (const auto& im : back.images) EXPECT_TRUE(im.points2d.empty());
}

TEST(ColmapExportTest, BadInputNamesFileAndLine) {
  const Scene s = MakeScene({0, 0, 0, 0, 0}, 0.0);
  const fs::path dir = TempDir("bad");
  WriteColmapText(dir, MakeColmapModel(s.map, s.tracks, {}));
  std::string points = ReadFileToString(dir / "points3D.txt");
  // Point a track element at a 2D point index that does not exist.
  const size_t eol = points.find('\n', points.find("\n5 ") + 1);
  points.insert(eol, " 1 9999");
  WriteFileAtomic(dir / "points3D.txt", points);
  try {
    ReadColmapText(dir);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("point 5"), std::string::npos)
        << e.what();
  }
  WriteFileAtomic(dir / "cameras.txt", "# c\n1 OPENCV 640 480 500 500 320\n");
  try {
    ReadColmapText(dir);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cameras.txt:2"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(MakeColmapModel(s.map, s.tracks, {"only_one.png"}), OutputError);
}

// Runs `colmap ARGS` with output to `log`; returns the exit status.
int RunColmap(const std::string& args, const fs::path& log) {
  const std::string cmd = "colmap " + args + " > '" + log.string() + "' 2>&1";
  return std::system(cmd.c_str());
}

// Debian's colmap reads the export: model_analyzer counts match, and a
// text -> binary -> text conversion by COLMAP gives back the same model.
TEST(ColmapExportTest, ColmapReadsTheExport) {
  if (std::system("command -v colmap > /dev/null 2>&1") != 0) {
    GTEST_SKIP() << "colmap is not installed (apt-get install colmap)";
  }
  const Scene s = MakeScene({-0.25, 0.08, 0.001, -0.0005, -0.02}, 0.3);
  ColmapExportReport report;
  const ColmapModel model = MakeColmapModel(s.map, s.tracks, {}, &report);
  const fs::path dir = TempDir("colmap");
  WriteColmapText(dir / "text", model);
  ASSERT_EQ(RunColmap("model_analyzer --path '" + (dir / "text").string() + "'",
                      dir / "analyzer.log"),
            0)
      << ReadFileToString(dir / "analyzer.log");
  const std::string log = ReadFileToString(dir / "analyzer.log");
  auto count = [&](const std::string& label) {
    std::smatch m;
    const std::regex re(label + ": ([0-9.]+)");
    return std::regex_search(log, m, re) ? std::stod(m[1]) : -1.0;
  };
  EXPECT_EQ(count("Cameras"), 1);
  EXPECT_EQ(count("Registered images"), 12);
  EXPECT_EQ(count("Points"), 60);
  EXPECT_EQ(count("Observations"), report.num_observations);
  double mean_point_error = 0;
  for (const auto& p : model.points) mean_point_error += p.error / 60.0;
  EXPECT_NEAR(count("Mean reprojection error"), mean_point_error, 1e-5);

  fs::create_directories(dir / "bin");
  fs::create_directories(dir / "text2");
  ASSERT_EQ(RunColmap("model_converter --output_type BIN --input_path '" +
                          (dir / "text").string() + "' --output_path '" +
                          (dir / "bin").string() + "'",
                      dir / "to_bin.log"),
            0);
  ASSERT_EQ(RunColmap("model_converter --output_type TXT --input_path '" +
                          (dir / "bin").string() + "' --output_path '" +
                          (dir / "text2").string() + "'",
                      dir / "to_txt.log"),
            0);
  const ColmapModel back = ReadColmapText(dir / "text2");
  ASSERT_EQ(back.cameras.size(), 1u);
  EXPECT_EQ(back.cameras[0].model, "FULL_OPENCV");
  for (size_t k = 0; k < 12; ++k) {
    EXPECT_NEAR(back.cameras[0].params[k], model.cameras[0].params[k], 1e-9);
  }
  ASSERT_EQ(back.images.size(), model.images.size());
  ASSERT_EQ(back.points.size(), model.points.size());
  size_t elements = 0;
  for (const auto& p : back.points) elements += p.track.size();
  EXPECT_EQ(static_cast<int>(elements), report.num_observations);
}

}  // namespace
}  // namespace monomap
