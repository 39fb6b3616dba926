// camera_mount.yaml: the camera's pose on the robot base (base_from_cam) in
// the forms calibration tools write (docs/dataset-format.md):
//   base_from_cam: {translation: [x, y, z], rotation_xyzw: [qx, qy, qz, qw]}
//     (or rotation_wxyz, or rotation: {x, y, z, w})
//   base_from_cam: [16 numbers]            4x4 row-major matrix
//   T_base_cam: [16 numbers]               Kalibr style (T_a_b = a_from_b)
//   T_cam_base: [16 numbers]               the inverse, cam_from_base
//   any of these keys holding an OpenCV matrix {rows: 4, cols: 4, data: [..]}
#pragma once

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <string>
#include <vector>

#include "monomap/geometry/rigid3.h"

namespace monomap {

// Parses the mount from the YAML text of `path` (`path` names the file in
// errors). Throws InputError naming the field for a missing, unknown or
// malformed form, a matrix whose rotation is not orthonormal with
// determinant +1 or whose last row is not [0 0 0 1], or a quaternion that is
// not of unit length.
Rigid3d ParseCameraMount(const std::string& yaml_text,
                         const std::filesystem::path& path);

// Parses YAML text, also as OpenCV's FileStorage writes it (a "%YAML:1.0"
// first line, which is not YAML 1.2). Throws InputError naming `path` and
// the line if malformed.
YAML::Node LoadYamlText(const std::string& text,
                        const std::filesystem::path& path);

// The `count` finite numbers of a YAML list; throws InputError naming
// `path` and `field` otherwise.
std::vector<double> YamlNumbers(const std::filesystem::path& path,
                                const YAML::Node& node,
                                const std::string& field, size_t count);

// A 4x4 row-major rigid transform: a list of 16 numbers or an OpenCV
// matrix map {rows: 4, cols: 4, data: [...]}. Throws InputError naming
// `path` and `field` unless it is one (see ParseCameraMount).
Rigid3d ParseRigidMatrix(const std::filesystem::path& path,
                         const YAML::Node& node, const std::string& field);

// Reads and parses `path`.
Rigid3d ReadCameraMount(const std::filesystem::path& path);

}  // namespace monomap
