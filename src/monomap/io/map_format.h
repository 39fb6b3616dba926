// The map directory written by `monomap build` and read by `render` and
// `localize`: map.json (camera, planes, features), one texture PNG per plane,
// points.ply (landmarks), trajectory.txt (TUM) and map.glb (glTF preview).
// See docs/map-format.md.
#pragma once

#include <filesystem>
#include <string>

#include "monomap/map/map.h"

namespace monomap {

// Value of map.json's "format" and the only "version" this code reads.
inline constexpr const char* kMapFormatName = "monomap.map";
inline constexpr int kMapFormatVersion = 1;

// File names inside a map directory.
inline constexpr const char* kMapJsonFile = "map.json";
inline constexpr const char* kMapPointsFile = "points.ply";
inline constexpr const char* kMapTrajectoryFile = "trajectory.txt";
inline constexpr const char* kMapGlbFile = "map.glb";

// Tolerances ReadMap accepts for unit normals, orthonormal in-plane axes and
// the frame origin lying on the plane (metres).
inline constexpr double kMapUnitTolerance = 1e-6;
inline constexpr double kMapOnPlaneToleranceM = 1e-6;

// Texture file name of a plane: "plane_<id>.png".
std::string PlaneTextureFileName(int plane_id);

// The map.json document (pretty-printed) for `map`.
std::string FormatMapJson(const Map& map);

// Writes all map files into `dir`, which must exist (the caller builds the
// map in an AtomicDirectory and commits it). Textures are written as 8-bit
// BGRA PNGs (grey or BGR textures get alpha 255). Throws OutputError on a
// plane that cannot be written (empty texture, fewer than 3 polygon
// vertices, duplicate id) or on IO failure.
void WriteMap(const std::filesystem::path& dir, const Map& map);

// Reads map.json, the plane textures (as BGRA) and trajectory.txt, and the
// landmarks from points.ply if that file exists. Throws InputError naming
// the file and, for map.json, the field path (e.g. "planes[2].normal") on a
// missing file, invalid JSON, wrong format/version or invalid values.
Map ReadMap(const std::filesystem::path& dir);

}  // namespace monomap
