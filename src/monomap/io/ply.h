// PLY point clouds: monomap's points.ply (xyz, color, feature id, plane
// label, per-point quality) and reading xyz from any PLY (ascii or binary
// little endian), e.g. a ground-truth surface cloud.
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
// x y z (float), red green blue (uchar), feature_id (int), plane (int),
// track_length (int, Landmark::num_observations), reprojection_error_px
// (float, mean) and triangulation_angle_deg (float). Written atomically;
// throws OutputError on a value the reader would refuse (negative count or
// error, angle outside [0, 180], an id beyond int).
void WriteLandmarksPly(const std::filesystem::path& path,
                       const std::vector<Landmark>& landmarks);

// Reads landmarks from a PLY vertex element: x y z are required; red green
// blue, feature_id, plane, track_length, reprojection_error_px and
// triangulation_angle_deg are read when present (otherwise color 0, id =
// vertex index, plane_id = -1, quality 0: files written before the quality
// properties still load). Fields that PLY does not hold (depth, covariance)
// are left at their defaults. Throws InputError naming the file and vertex on
// anything malformed or truncated, or a quality value out of range.
std::vector<Landmark> ReadLandmarksPly(const std::filesystem::path& path);

}  // namespace monomap
