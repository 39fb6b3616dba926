// Synthetic indoor worlds made of textured planes, with exact ground truth:
// the structure a ground robot drives through in the simulator. World frame:
// z up, floor at z = 0.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "monomap/map/map.h"

namespace monomap {

struct World {
  std::string name;
  // Ground-truth structure: bounded planes with procedural BGRA textures
  // (alpha 255 everywhere). Planes may occlude each other; none overlap
  // coplanarly.
  std::vector<TexturedPlane> planes;
  // Base positions (x, y) on the floor the robot's path passes through, in
  // order; see robot.h.
  std::vector<Eigen::Vector2d> path_keypoints;
  // True if the path returns to its first keypoint (a loop).
  bool path_closed = false;
  // Index in `planes` of the floor (where specular highlights appear).
  int floor_plane = -1;
  // Ceiling lights (world points) whose mirror images make the specular
  // highlights on the floor.
  std::vector<Eigen::Vector3d> lights;

  // Bytes held by the textures.
  size_t TextureBytes() const;
};

// Names MakeWorld accepts: "hallway", "lab-corner", "room", "office".
std::vector<std::string> WorldNames();

// Texture resolution MakeWorld uses unless told otherwise (texels/m).
inline constexpr double kDefaultWorldPixelsPerMeter = 450.0;

// Builds the named world; `seed` drives the procedural textures, so the same
// (name, seed, pixels_per_meter) gives identical worlds. Lower
// pixels_per_meter gives coarser, cheaper textures (tests). Throws
// OptionsError listing the valid names for an unknown name, or for
// pixels_per_meter outside [20, 2000].
World MakeWorld(const std::string& name, uint64_t seed,
                double pixels_per_meter = kDefaultWorldPixelsPerMeter);

// splitmix64 of a seed and a stream index: independent, reproducible seeds
// for the simulator's random generators.
uint64_t SimMixSeed(uint64_t seed, uint64_t stream);

// A rectangle plane: X = origin + s u + t v, s in [0, width], t in [0,
// height], normal u x v, and a texture of ceil(width * ppm) x ceil(height *
// ppm) texels (opaque black: the caller paints it). u and v must be
// orthonormal.
TexturedPlane MakeRectanglePlane(int id, const Eigen::Vector3d& origin,
                                 const Eigen::Vector3d& u_axis,
                                 const Eigen::Vector3d& v_axis, double width,
                                 double height, double pixels_per_meter);

}  // namespace monomap
