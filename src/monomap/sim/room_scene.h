// A small room for the localization tests and benchmark: a 4 x 3 m room
// (floor and four 1.2 m walls with random-blob textures), a camera with
// mild lens distortion on a planar robot, and "live" images rendered from
// ground-truth poses with the map's Renderer, then distorted, with a gain
// change and noise. Header-only; not part of the library API. (Point-track
// scenes: synthetic_scene.h; ray-cast textured planes:
// textured_plane_scene.h.)
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <opencv2/imgproc.hpp>

#include "monomap/camera/camera.h"
#include "monomap/geometry/plane.h"
#include "monomap/geometry/pose2d.h"
#include "monomap/map/map.h"
#include "monomap/rendering/renderer.h"
#include "monomap/util/angles.h"

namespace monomap::testing {

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
    const cv::Point c(rng.uniform(0, cols), rng.uniform(0, rows));
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
  cv::remap(pinhole, raw, map_x, map_y, cv::INTER_LINEAR,
            cv::BORDER_REPLICATE);
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

}  // namespace monomap::testing
