// Synthetic textured-plane scenes for the texture tests and benchmark: an
// exact per-pixel ray caster through a distorted camera, procedural plane
// textures and feature tracks. Header-only; not part of the library API.
// (Point-track scenes: synthetic_scene.h; the localization room:
// room_scene.h.)
#pragma once

#include <cmath>
#include <functional>
#include <random>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <tbb/parallel_for.h>

#include "monomap/camera/camera.h"
#include "monomap/geometry/rigid3.h"
#include "monomap/map/map.h"

namespace monomap::testing {

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
      b.centre = lo + (hi - lo).cwiseProduct(Eigen::Vector2d(u(rng), u(rng)));
      b.radius = 0.01 + 0.03 * u(rng);
      b.bgr = Eigen::Vector3f(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5) * 160;
      t.blobs.push_back(b);
    }
    return t;
  }

  Eigen::Vector3f operator()(const Eigen::Vector2d& st) const {
    constexpr double kTwoPi = 6.283185307179586;
    const double checker =
        std::tanh(2.5 * std::sin(kTwoPi * st.x() / period) *
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
    rays_.resize(static_cast<size_t>(camera.width) * camera.height * ss_ *
                 ss_);
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
        lo + (hi - lo).cwiseProduct(Eigen::Vector2d(0.05 + 0.9 * u(rng),
                                                    0.05 + 0.9 * u(rng)));
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

}  // namespace monomap::testing
