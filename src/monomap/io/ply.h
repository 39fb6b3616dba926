// PLY point clouds: monomap's points.ply (xyz, color, feature id, plane
// label) and reading xyz from any PLY (ascii or binary little endian), e.g.
// a ground-truth surface cloud.
#pragma once

#include <filesystem>
#include <vector>

#include <Eigen/Core>

#include "monomap/map/map.h"

namespace monomap {

// Reads the x, y, z properties of the vertex element of a PLY file (ascii
// or binary_little_endian; float or double). Throws InputError naming the
// file on anything malformed or truncated.
std::vector<Eigen::Vector3d> ReadPlyPoints(const std::filesystem::path& path);

// Writes landmarks as a binary little-endian PLY with properties
// x y z (float), red green blue (uchar), feature_id (int), plane (int).
// Written atomically.
void WriteLandmarksPly(const std::filesystem::path& path,
                       const std::vector<Landmark>& landmarks);

// Reads landmarks from a PLY vertex element: x y z are required; red green
// blue, feature_id and plane are read when present (otherwise color 0,
// id = vertex index, plane_id = -1). Fields that PLY does not hold
// (observation counts, errors, depth) are left at their defaults. Throws
// InputError naming the file on anything malformed or truncated.
std::vector<Landmark> ReadLandmarksPly(const std::filesystem::path& path);

}  // namespace monomap
