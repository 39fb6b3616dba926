// glTF 2.0 binary (.glb) export of a map: one textured, double-sided mesh
// per plane, for viewing the map in any glTF viewer (Blender, three.js).
#pragma once

#include <filesystem>
#include <vector>

#include <Eigen/Core>

#include "monomap/geometry/polygon.h"
#include "monomap/map/map.h"

namespace monomap {

// Triangulates a simple polygon (either orientation) by ear clipping.
// Returns vertex index triples, counter-clockwise in (s, t) coordinates;
// n - 2 triangles for a simple polygon with n >= 3 vertices. Repeated or
// collinear vertices are tolerated; if no ear can be found (self-
// intersecting input) the rest is closed with a fan.
std::vector<Eigen::Vector3i> TriangulatePolygon(const Polygon2d& polygon);

// Optional content of map.glb beyond the textured planes.
struct GlbOptions {
  // A node "camera_path": the refined camera centres as a LINE_STRIP.
  bool camera_path = false;
  // A node "landmarks": the landmarks as POINTS with COLOR_0.
  bool points = false;
  // Convert the world (z up) to glTF's +Y up: (x, y, z) -> (x, z, -y), for
  // viewers that assume glTF's convention.
  bool y_up = false;
};

// Writes `map` as a .glb (atomically): per plane with >= 3 polygon vertices
// and a texture, a node "plane_<id>" with a mesh whose vertices are the
// polygon corners in world coordinates (float POSITION, NORMAL = plane
// normal, TEXCOORD_0 = (s * ppm / width, t * ppm / height)), indices from
// TriangulatePolygon, and a material with the texture PNG (embedded in the
// binary buffer) as baseColorTexture, doubleSided, alphaMode MASK. Positions
// stay in the map's world frame unless options.y_up; options add the camera
// path and the landmarks. Throws OutputError on failure.
void WriteMapGlb(const std::filesystem::path& path, const Map& map,
                 const GlbOptions& options = GlbOptions());

}  // namespace monomap
