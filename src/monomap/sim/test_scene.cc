#include "monomap/sim/test_scene.h"

#include <algorithm>
#include <cmath>
#include <random>

#include "monomap/util/angles.h"
#include "monomap/util/error.h"
#include "monomap/util/random.h"

namespace monomap::testing {
namespace {

TestScene MakePointScene(const TestSceneOptions& options) {
  const PointLayoutOptions& p = options.points;
  TestScene scene;
  scene.camera = options.camera.value_or(SyntheticCamera());
  const Camera& camera = scene.camera;
  std::mt19937_64 rng(options.seed);
  // Trajectory: sideways travel with a gentle vertical wave and a few
  // degrees of yaw/pitch wobble, so rotations are not all identical.
  const int n = options.num_frames;
  for (int i = 0; i < n; ++i) {
    const double phase = 2.0 * M_PI * i / 60.0;
    const Eigen::Vector3d center(p.step_m * i, 0.005 * std::sin(phase),
                                 0.003 * std::cos(0.7 * phase));
    const Eigen::Quaterniond rotation =
        QuaternionFromRotationVector(Eigen::Vector3d(
            DegToRad(1.5) * std::sin(0.5 * phase),
            DegToRad(3.0) * std::sin(phase), DegToRad(1.0) * std::cos(phase)));
    scene.world_from_cam.emplace_back(rotation, center);
  }
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, 1.0);
  for (int t = 0; t < p.num_tracks; ++t) {
    int length = p.min_track_length +
                 static_cast<int>(uniform(rng) * (p.max_track_length -
                                                  p.min_track_length + 1));
    length = std::clamp(length, 1, n);
    const int start = static_cast<int>(uniform(rng) * (n - length + 1));
    const int mid = std::min(start + length / 2, n - 1);
    // A pixel in the central part of the middle view, so the point stays in
    // the image over the whole track, back-projected to a random depth.
    const double v = camera.cy + (uniform(rng) - 0.5) * 360.0;
    const Eigen::Vector2d px(camera.cx + (uniform(rng) - 0.5) * 440.0, v);
    const double depth =
        p.min_depth_m + uniform(rng) * (p.max_depth_m - p.min_depth_m);
    const Eigen::Vector3d x_in_cam =
        Eigen::Vector3d(camera.NormalizedFromImage(px).homogeneous()) * depth;
    const Eigen::Vector3d x = scene.world_from_cam[mid] * x_in_cam;
    Track track;
    track.id = t;
    for (int f = start; f < start + length; ++f) {
      const Eigen::Vector3d xc = scene.world_from_cam[f].Inverse() * x;
      if (xc.z() <= 0) continue;
      Eigen::Vector2d obs = camera.ImageFromCam(xc);
      if (!camera.InImage(obs, 2.0)) continue;
      obs += p.pixel_noise_px * DrawLastFirst<Eigen::Vector2d>(noise, rng);
      track.observations.push_back({f, obs});
    }
    scene.points.push_back(x);
    scene.tracks.push_back(std::move(track));
  }
  return scene;
}

TestScene MakeDeskScene(const TestSceneOptions& options) {
  const DeskLayoutOptions& d = options.desk;
  TestScene scene;
  scene.camera = options.camera.value_or(SyntheticCamera());
  scene.world_from_cam = options.world_from_cam;
  PlaneSegment desk =
      HorizontalRectangle(d.plane_id, 0.0, 0.0, 0.0, d.width_m, d.depth_m);
  desk.frame.origin -=
      Eigen::Vector3d(d.origin_shift_m.x(), d.origin_shift_m.y(), 0.0);
  for (auto& v : desk.polygon) v += d.origin_shift_m;
  MakePlaneFeatures(scene.camera, scene.world_from_cam, d.num_features,
                    d.first_feature_id, d.feature_seed, &desk, &scene.landmarks,
                    &scene.tracks);
  scene.segments.push_back(desk);
  if (d.texture_blobs > 0) {
    const auto texture = ProceduralTexture::Make(
        d.texture_seed, {0.0, 0.0}, d.texture_extent_m, d.texture_blobs);
    scene.planes.push_back({desk, [texture](int, const Eigen::Vector2d& st) {
                              return texture(st);
                            }});
  }
  return scene;
}

TestScene MakeRoomScene(const TestSceneOptions& options) {
  const RoomLayoutOptions& r = options.room;
  TestScene scene;
  scene.map = RoomMap(r.pixels_per_meter, r.texture_seed);
  scene.camera = options.camera.value_or(LiveCamera());
  scene.base_from_cam = BaseFromCam();
  for (const Pose2d& base : r.base_poses) {
    scene.world_from_cam.push_back(
        WorldFromCamOfBase(base, scene.base_from_cam));
  }
  if (!r.render_images) return scene;
  const Renderer renderer(scene.map);
  for (size_t i = 0; i < scene.world_from_cam.size(); ++i) {
    scene.images.push_back(LiveImage(renderer, scene.camera,
                                     scene.world_from_cam[i], r.gain, r.offset,
                                     r.noise_sigma, options.seed + i));
  }
  return scene;
}

}  // namespace

Camera SyntheticCamera() {
  Camera c;
  c.width = 752;
  c.height = 480;
  c.fx = 420.0;
  c.fy = 420.0;
  c.cx = 375.5;
  c.cy = 239.5;
  c.distortion = {-0.3, 0.08, 0.0005, -0.0003, 0.0};
  return c;
}

void TestSceneOptions::Check() const {
  if (layout == TestLayout::kPoints) {
    CheckOption(num_frames >= 2, "num_frames", "must be >= 2");
    CheckOption(points.min_track_length >= 1 &&
                    points.max_track_length >= points.min_track_length,
                "min_track_length/max_track_length", "bad range");
  }
  if (layout == TestLayout::kDesk) {
    CheckOption(!world_from_cam.empty(), "world_from_cam",
                "the desk layout needs the camera poses");
    CheckOption(desk.width_m > 0 && desk.depth_m > 0, "desk.width_m/depth_m",
                "must be > 0");
  }
  if (layout == TestLayout::kRoom) {
    CheckOption(room.pixels_per_meter > 0, "room.pixels_per_meter",
                "must be > 0");
  }
}

TestScene MakeTestScene(const TestSceneOptions& options) {
  options.Check();
  switch (options.layout) {
    case TestLayout::kPoints:
      return MakePointScene(options);
    case TestLayout::kDesk:
      return MakeDeskScene(options);
    case TestLayout::kRoom:
      return MakeRoomScene(options);
  }
  throw OptionsError("layout: unknown test scene layout");
}

std::vector<Rigid3d> SimulateOdometryDrift(
    const std::vector<Rigid3d>& world_from_cam,
    const OdometryDriftOptions& options) {
  std::vector<Rigid3d> odometry;
  if (world_from_cam.empty()) return odometry;
  std::mt19937_64 rng(options.seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  const Eigen::Vector3d drift_axis =
      Eigen::Vector3d(0.3, 1.0, 0.2).normalized();
  odometry.push_back(world_from_cam[0]);
  for (size_t i = 0; i + 1 < world_from_cam.size(); ++i) {
    const Rigid3d delta = world_from_cam[i].Inverse() * world_from_cam[i + 1];
    const double step = delta.translation.norm();
    const Eigen::Vector3d t =
        (1.0 + options.scale_error) * delta.translation +
        options.translation_noise_fraction * step *
            DrawLastFirst<Eigen::Vector3d>(noise, rng);
    const Eigen::Vector3d w =
        drift_axis * DegToRad(options.rotation_drift_deg_per_m * step) +
        DegToRad(options.rotation_noise_deg) *
            DrawLastFirst<Eigen::Vector3d>(noise, rng);
    const Rigid3d noisy(delta.rotation * QuaternionFromRotationVector(w), t);
    odometry.push_back(odometry.back() * noisy);
  }
  return odometry;
}

}  // namespace monomap::testing
