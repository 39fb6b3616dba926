// Multi-view triangulation math (no I/O, no options): linear DLT and
// angle/cheirality helpers. The nonlinear refinement lives in
// triangulation/.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "monomap/geometry/rigid3.h"

namespace monomap {

// Linear (DLT) triangulation from >= 2 views. `normalized` holds undistorted
// normalized image coordinates (x/z, y/z) seen from each `cam_from_world`.
// Returns false if the system is degenerate or the point is at infinity.
bool TriangulateLinear(const std::vector<Rigid3d>& cams_from_world,
                       const std::vector<Eigen::Vector2d>& normalized,
                       Eigen::Vector3d* x_in_world);

// Largest angle (radians, found in O(n)) between viewing rays from the camera centres to
// `x_in_world`: small angles mean poorly conditioned depth.
double MaxTriangulationAngle(const std::vector<Rigid3d>& cams_from_world,
                             const Eigen::Vector3d& x_in_world);

// Depth of a world point in a camera (z of x_in_cam).
inline double DepthInCamera(const Rigid3d& cam_from_world,
                            const Eigen::Vector3d& x_in_world) {
  return (cam_from_world * x_in_world).z();
}

}  // namespace monomap
