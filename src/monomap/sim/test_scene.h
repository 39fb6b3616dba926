// Synthetic scenes with exact truth for the tests and benchmarks: one
// generator, MakeTestScene, whose options choose a layout
//   kPoints  random points in front of a camera sliding sideways, with
//            KLT-like tracks of raw distorted pixels (triangulation, lens
//            residuals);
//   kDesk    one textured horizontal rectangle with features, seen from
//            given poses, to ray-cast (homographies, mosaics);
//   kRoom    a 4 x 3 m room of blob-textured planes as a Map, a camera on a
//            planar robot, optionally live images rendered with the map's
//            Renderer (localization);
// and the pieces it is made of, for tests that compose their own scene:
// cameras, poses, textures, planes, features, the ray caster, live images
// and drifting odometry. Not part of the library API. (The full simulator,
// worlds driven through by a robot: simulate.h.)
#pragma once

#include <tbb/parallel_for.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <random>
#include <vector>

#include "monomap/camera/camera.h"
#include "monomap/geometry/plane.h"
#include "monomap/geometry/pose2d.h"
#include "monomap/geometry/rigid3.h"
#include "monomap/map/map.h"
#include "monomap/rendering/renderer.h"
#include "monomap/util/angles.h"
#include "monomap/util/random.h"

namespace monomap::testing {

// ---------------------------------------------------------------------------
// Cameras, poses and textures.

// The plumb_bob test camera of the kPoints layout: 752x480, f=420,
// k1=-0.3, k2=0.08, small tangential terms.
Camera SyntheticCamera();

// ---------------------------------------------------------------------------
// Desk scenes: poses, procedural textures, planes, features, ray casting.

// world_from_cam of a camera at `eye` looking at `target`; `down` is the
// world direction that should appear downwards in the image.
inline Rigid3d LookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
                      const Eigen::Vector3d& down) {
  const Eigen::Vector3d z = (target - eye).normalized();
  const Eigen::Vector3d x = down.cross(z).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d r;
  r.col(0) = x;
  r.col(1) = y;
  r.col(2) = z;
  return Rigid3d(Eigen::Quaterniond(r), eye);
}

// A soft checkerboard plus coloured Gaussian blobs, BGR in [0, 255].
struct ProceduralTexture {
  struct Blob {
    Eigen::Vector2d centre;
    double radius;
    Eigen::Vector3f bgr;
  };
  double period = 0.05;  // checker period (m)
  std::vector<Blob> blobs;

  static ProceduralTexture Make(uint32_t seed, const Eigen::Vector2d& lo,
                                const Eigen::Vector2d& hi, int num_blobs) {
    ProceduralTexture t;
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int i = 0; i < num_blobs; ++i) {
      Blob b;
      b.centre = lo + (hi - lo).cwiseProduct(
                          DrawLastFirst<Eigen::Vector2d>(u, rng));
      b.radius = 0.01 + 0.03 * u(rng);
      const Eigen::Vector3d c = DrawLastFirst<Eigen::Vector3d>(u, rng);
      b.bgr = Eigen::Vector3f(c[0] - 0.5, c[1] - 0.5, c[2] - 0.5) * 160;
      t.blobs.push_back(b);
    }
    return t;
  }

  Eigen::Vector3f operator()(const Eigen::Vector2d& st) const {
    constexpr double kTwoPi = 6.283185307179586;
    const double checker = std::tanh(2.5 * std::sin(kTwoPi * st.x() / period) *
                                     std::sin(kTwoPi * st.y() / period));
    const float base = static_cast<float>(120.0 + 60.0 * checker);
    Eigen::Vector3f c(base, base, base);
    for (const Blob& b : blobs) {
      const double w = std::exp(-(st - b.centre).squaredNorm() /
                                (2.0 * b.radius * b.radius));
      c += static_cast<float>(w) * b.bgr;
    }
    return c.cwiseMax(0.0f).cwiseMin(255.0f);
  }
};

// A plane of the scene and its colour, which may depend on the frame
// (moving objects, highlights): colour(frame, st) in BGR [0, 255].
struct ScenePlane {
  PlaneSegment segment;
  std::function<Eigen::Vector3f(int frame, const Eigen::Vector2d& st)> color;
};

// Renders the scene through the distorted camera: each pixel is the mean of
// supersample^2 exact rays (first plane hit along each ray).
class RayCaster {
 public:
  RayCaster(const Camera& camera, int supersample = 2)
      : camera_(camera), ss_(supersample) {
    rays_.resize(static_cast<size_t>(camera.width) * camera.height * ss_ * ss_);
    tbb::parallel_for(0, camera.height, [&](int v) {
      for (int u = 0; u < camera.width; ++u) {
        for (int i = 0; i < ss_; ++i) {
          for (int j = 0; j < ss_; ++j) {
            const Eigen::Vector2d px(u - 0.5 + (j + 0.5) / ss_,
                                     v - 0.5 + (i + 0.5) / ss_);
            rays_[Index(u, v, i, j)] =
                camera_.NormalizedFromImage(px).homogeneous();
          }
        }
      }
    });
  }

  // BGR 8-bit image of `frame`; colours are multiplied by `gain`, Gaussian
  // noise of `noise_sigma` grey levels is added (seeded by the frame).
  cv::Mat Render(const Rigid3d& world_from_cam,
                 const std::vector<ScenePlane>& planes, int frame,
                 double gain = 1.0, double noise_sigma = 0.0,
                 float background = 30.0f) const {
    cv::Mat image(camera_.height, camera_.width, CV_8UC3);
    const Eigen::Matrix3d r = world_from_cam.RotationMatrix();
    const Eigen::Vector3d c = world_from_cam.translation;
    tbb::parallel_for(0, camera_.height, [&](int v) {
      std::mt19937 rng(static_cast<uint32_t>(frame * 100003 + v));
      std::normal_distribution<double> noise(0.0, noise_sigma);
      for (int u = 0; u < camera_.width; ++u) {
        Eigen::Vector3f sum = Eigen::Vector3f::Zero();
        for (int i = 0; i < ss_; ++i) {
          for (int j = 0; j < ss_; ++j) {
            const Eigen::Vector3d d = r * rays_[Index(u, v, i, j)];
            double best = std::numeric_limits<double>::infinity();
            Eigen::Vector3f color(background, background, background);
            for (const ScenePlane& p : planes) {
              const Plane& pl = p.segment.plane;
              const double denom = pl.normal.dot(d);
              if (std::abs(denom) < 1e-12) continue;
              const double lambda = -pl.SignedDistance(c) / denom;
              if (lambda <= 0 || lambda >= best) continue;
              const Eigen::Vector2d st =
                  p.segment.frame.ToPlane(c + lambda * d);
              if (!PointInPolygon(p.segment.polygon, st)) continue;
              best = lambda;
              color = p.color(frame, st);
            }
            sum += color;
          }
        }
        sum *= static_cast<float>(gain) / (ss_ * ss_);
        cv::Vec3b& out = image.at<cv::Vec3b>(v, u);
        for (int ch = 0; ch < 3; ++ch) {
          const double n = noise_sigma > 0 ? noise(rng) : 0.0;
          out[ch] = cv::saturate_cast<uint8_t>(sum[ch] + n);
        }
      }
    });
    return image;
  }

 private:
  size_t Index(int u, int v, int i, int j) const {
    return ((static_cast<size_t>(v) * camera_.width + u) * ss_ + i) * ss_ + j;
  }
  Camera camera_;
  int ss_;
  std::vector<Eigen::Vector3d> rays_;
};

// An axis-aligned rectangle [0, w] x [0, h] on the plane z = height, frame
// origin at (x0, y0, height), u = world x, v = world y.
inline PlaneSegment HorizontalRectangle(int id, double x0, double y0,
                                        double height, double w, double h) {
  PlaneSegment s;
  s.id = id;
  s.plane.normal = Eigen::Vector3d::UnitZ();
  s.plane.offset = -height;
  s.frame.origin = Eigen::Vector3d(x0, y0, height);
  s.frame.u_axis = Eigen::Vector3d::UnitX();
  s.frame.v_axis = Eigen::Vector3d::UnitY();
  s.polygon = {{0, 0}, {w, 0}, {w, h}, {0, h}};
  return s;
}

// `count` landmarks uniformly inside the segment's polygon bounds (ids from
// first_id), attached to the segment (plane_id, inlier_ids), and their exact
// tracks in every frame where they project into the image.
inline void MakePlaneFeatures(const Camera& camera,
                              const std::vector<Rigid3d>& world_from_cam,
                              int count, FeatureId first_id, uint32_t seed,
                              PlaneSegment* segment,
                              std::vector<Landmark>* landmarks,
                              std::vector<Track>* tracks) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Eigen::Vector2d lo, hi;
  PolygonBounds(segment->polygon, &lo, &hi);
  for (int i = 0; i < count; ++i) {
    Landmark l;
    l.id = first_id + i;
    const Eigen::Vector2d st =
        lo + (hi - lo).cwiseProduct(
                 Eigen::Vector2d::Constant(0.05) +
                 0.9 * DrawLastFirst<Eigen::Vector2d>(u, rng));
    l.x_in_world = segment->frame.ToWorld(st);
    l.plane_id = segment->id;
    segment->inlier_ids.push_back(l.id);
    segment->inlier_st.push_back(st);
    Track t;
    t.id = l.id;
    for (int f = 0; f < static_cast<int>(world_from_cam.size()); ++f) {
      const Eigen::Vector3d x = world_from_cam[f].Inverse() * l.x_in_world;
      if (x.z() <= 0.05) continue;
      const Eigen::Vector2d px = camera.ImageFromCam(x);
      if (!camera.InImage(px, 2.0)) continue;
      t.observations.push_back({f, px});
    }
    l.num_observations = static_cast<int>(t.observations.size());
    landmarks->push_back(l);
    tracks->push_back(t);
  }
}

// ---------------------------------------------------------------------------
// The localization room: a Map of blob-textured planes, a camera on a
// planar robot, live images.

// Random blobs of random grey on a smooth random background, opaque BGRA.
inline cv::Mat BlobTexture(int cols, int rows, uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat noise(std::max(2, rows / 16), std::max(2, cols / 16), CV_32F);
  rng.fill(noise, cv::RNG::UNIFORM, 60.0, 200.0);
  cv::Mat grey;
  cv::resize(noise, grey, cv::Size(cols, rows), 0, 0, cv::INTER_CUBIC);
  grey.convertTo(grey, CV_8U);
  const int blobs = cols * rows / 1500;
  for (int i = 0; i < blobs; ++i) {
    const int y = rng.uniform(0, rows);  // y first: util/random.h
    const cv::Point c(rng.uniform(0, cols), y);
    const int r = rng.uniform(3, 18);
    cv::circle(grey, c, r, cv::Scalar(rng.uniform(0, 256)), cv::FILLED,
               cv::LINE_AA);
  }
  cv::GaussianBlur(grey, grey, cv::Size(3, 3), 0.8);
  cv::Mat bgra;
  cv::cvtColor(grey, bgra, cv::COLOR_GRAY2BGRA);
  return bgra;
}

// A rectangle origin + [0, su] u + [0, sv] v; the texture faces u x v.
inline TexturedPlane MakeRect(int id, const Eigen::Vector3d& origin,
                              const Eigen::Vector3d& u,
                              const Eigen::Vector3d& v, double su, double sv,
                              double ppm, uint64_t seed) {
  TexturedPlane p;
  p.id = id;
  p.plane.normal = u.cross(v).normalized();
  p.plane.offset = -p.plane.normal.dot(origin);
  p.frame = MakePlaneFrame(p.plane, origin, u);
  p.pixels_per_meter = ppm;
  p.texture = BlobTexture(static_cast<int>(std::lround(su * ppm)),
                          static_cast<int>(std::lround(sv * ppm)), seed);
  p.polygon = {{0, 0}, {su, 0}, {su, sv}, {0, sv}};
  return p;
}

// Floor x in [-1, 3], y in [-1.5, 1.5], walls 1.2 m high, normals inwards.
inline Map RoomMap(double ppm = 200, uint64_t seed = 7) {
  using V = Eigen::Vector3d;
  Map map;
  const double x0 = -1, x1 = 3, y0 = -1.5, y1 = 1.5, h = 1.2;
  map.planes.push_back(MakeRect(0, V(x0, y0, 0), V::UnitX(), V::UnitY(),
                                x1 - x0, y1 - y0, ppm, seed));
  // Front wall x = x1, normal -x: u = -y, v = z.
  map.planes.push_back(MakeRect(1, V(x1, y1, 0), -V::UnitY(), V::UnitZ(),
                                y1 - y0, h, ppm, seed + 1));
  // Back wall x = x0, normal +x: u = y, v = z.
  map.planes.push_back(MakeRect(2, V(x0, y0, 0), V::UnitY(), V::UnitZ(),
                                y1 - y0, h, ppm, seed + 2));
  // Left wall y = y1, normal -y: u = x, v = z.
  map.planes.push_back(MakeRect(3, V(x0, y1, 0), V::UnitX(), V::UnitZ(),
                                x1 - x0, h, ppm, seed + 3));
  // Right wall y = y0, normal +y: u = -x, v = z.
  map.planes.push_back(MakeRect(4, V(x1, y0, 0), -V::UnitX(), V::UnitZ(),
                                x1 - x0, h, ppm, seed + 4));
  return map;
}

// 320 x 240 camera with mild barrel distortion.
inline Camera LiveCamera() {
  Camera c;
  c.width = 320;
  c.height = 240;
  c.fx = c.fy = 250;
  c.cx = 159.5;
  c.cy = 119.5;
  c.distortion = {-0.05, 0.01, 0, 0, 0};
  return c;
}

// Camera 0.5 m above the base, 0.1 m ahead, looking along base +x and
// pitched 20 degrees down.
inline Rigid3d BaseFromCam() {
  const double pitch = DegToRadMulDiv(20.0);
  const Eigen::Vector3d z(std::cos(pitch), 0, -std::sin(pitch));
  const Eigen::Vector3d x(0, -1, 0);
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d r;
  r << x, y, z;
  return Rigid3d(Eigen::Quaterniond(r), Eigen::Vector3d(0.1, 0, 0.5));
}

// Raw (distorted) live image of `camera` at `pose`: rendered as a pinhole
// at full size, distorted by remapping, then gain * I + offset + noise.
inline cv::Mat LiveImage(const Renderer& renderer, const Camera& camera,
                         const Rigid3d& pose, double gain, double offset,
                         double noise_sigma, uint64_t seed) {
  cv::Mat pinhole;
  renderer.Render(camera.Pinhole(), pose, &pinhole);
  cv::Mat map_x(camera.height, camera.width, CV_32F);
  cv::Mat map_y(camera.height, camera.width, CV_32F);
  for (int v = 0; v < camera.height; ++v) {
    for (int u = 0; u < camera.width; ++u) {
      const Eigen::Vector2d xn = camera.NormalizedFromImage({u, v});
      const Eigen::Vector2d px = camera.PinholeFromNormalized(xn);
      map_x.at<float>(v, u) = static_cast<float>(px.x());
      map_y.at<float>(v, u) = static_cast<float>(px.y());
    }
  }
  cv::Mat raw;
  cv::remap(pinhole, raw, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  cv::Mat f;
  raw.convertTo(f, CV_32F, gain, offset);
  if (noise_sigma > 0) {
    cv::Mat n(f.size(), CV_32F);
    cv::RNG rng(seed);
    rng.fill(n, cv::RNG::NORMAL, 0.0, noise_sigma);
    f += n;
  }
  cv::Mat out;
  f.convertTo(out, CV_8U);
  return out;
}

// ---------------------------------------------------------------------------
// Drifting odometry.

struct OdometryDriftOptions {
  // Random walk: per-axis Gaussian translation noise per step, as a
  // fraction of the step length.
  double translation_noise_fraction = 0.05;
  // Relative scale error of every step.
  double scale_error = 0.005;
  // Systematic rotation drift (degrees per metre travelled) about a fixed
  // axis, plus per-axis Gaussian rotation noise per frame (degrees).
  double rotation_drift_deg_per_m = 1.0;
  double rotation_noise_deg = 0.01;
  uint64_t seed = 2;
};

// Odometry as it would come from a drifting sensor: anchored at the first
// true pose, each relative motion corrupted as described by the options.
std::vector<Rigid3d> SimulateOdometryDrift(
    const std::vector<Rigid3d>& world_from_cam,
    const OdometryDriftOptions& options);

// ---------------------------------------------------------------------------
// The generator.

enum class TestLayout { kPoints, kDesk, kRoom };

// kPoints: the camera travels sideways along world x with a gentle wave and
// wobble; each track is one point.
struct PointLayoutOptions {
  // Camera travel per frame (m).
  double step_m = 0.003;
  // Tracks (one 3D point each).
  int num_tracks = 500;
  // Track length, uniform in [min, max] frames (clipped at the sequence).
  int min_track_length = 10;
  int max_track_length = 50;
  // Depth (m) of a point in the camera at the middle of its track.
  double min_depth_m = 0.3;
  double max_depth_m = 0.6;
  // Gaussian noise (px, per axis) on the observations.
  double pixel_noise_px = 0.0;
};

// kDesk: a width_m x depth_m rectangle on z = 0 (HorizontalRectangle),
// features on it (MakePlaneFeatures), and a procedural texture.
struct DeskLayoutOptions {
  int plane_id = 0;
  double width_m = 0.6;
  double depth_m = 0.4;
  // The segment's frame origin is moved by -origin_shift_m (and its
  // polygon by +origin_shift_m): the same rectangle, in a frame whose
  // origin is not the polygon's corner.
  Eigen::Vector2d origin_shift_m = Eigen::Vector2d::Zero();
  // Features: count, first id, seed.
  int num_features = 60;
  FeatureId first_feature_id = 0;
  uint32_t feature_seed = 1;
  // Texture (ProceduralTexture): seed, blobs and the extent (m, from the
  // frame origin) they are spread over; 0 blobs: no ScenePlane.
  uint32_t texture_seed = 1;
  int texture_blobs = 0;
  Eigen::Vector2d texture_extent_m{0.6, 0.4};
};

// kRoom: RoomMap, BaseFromCam; the robot's base poses are given.
struct RoomLayoutOptions {
  // Texture resolution (texels per metre) and seed of the planes.
  double pixels_per_meter = 200;
  uint64_t texture_seed = 7;
  // The robot's base poses; world_from_cam follows through the mount.
  std::vector<Pose2d> base_poses;
  // Also render a live image per pose (LiveImage: gain * I + offset +
  // noise, noise seeded with options.seed + frame index).
  bool render_images = false;
  double gain = 1.0;
  double offset = 0.0;
  double noise_sigma = 0.0;
};

struct TestSceneOptions {
  TestLayout layout = TestLayout::kPoints;
  // kPoints: frames of the trajectory (kDesk: world_from_cam's size, kRoom:
  // room.base_poses').
  int num_frames = 60;
  // kPoints: points and noise; kRoom: image noise.
  uint64_t seed = 1;
  // The camera; empty: SyntheticCamera() (kPoints, kDesk) or LiveCamera()
  // (kRoom).
  std::optional<Camera> camera;
  // kDesk: the camera poses.
  std::vector<Rigid3d> world_from_cam;
  PointLayoutOptions points;
  DeskLayoutOptions desk;
  RoomLayoutOptions room;

  void Check() const;
};

struct TestScene {
  Camera camera;
  std::vector<Rigid3d> world_from_cam;  // truth, one per frame
  // kPoints: points[i] is the truth of tracks[i] (tracks[i].id == i).
  std::vector<Eigen::Vector3d> points;
  std::vector<Track> tracks;           // kPoints, kDesk
  std::vector<PlaneSegment> segments;  // kDesk: the desk with its inliers
  std::vector<Landmark> landmarks;     // kDesk: truth of the features
  std::vector<ScenePlane> planes;      // kDesk: to ray-cast (if textured)
  Map map;                             // kRoom: the textured planes
  Rigid3d base_from_cam;               // kRoom: the mount
  std::vector<cv::Mat> images;         // kRoom with render_images
};

// The scene the options describe. Deterministic given the options; throws
// OptionsError for bad ones.
TestScene MakeTestScene(const TestSceneOptions& options);

}  // namespace monomap::testing
