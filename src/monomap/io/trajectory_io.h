// TUM trajectory files: `timestamp tx ty tz qx qy qz qw` per line, each the
// camera-to-world pose world_from_cam; '#' starts a comment line.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "monomap/map/map.h"

namespace monomap {

// Reads a TUM trajectory. Throws InputError naming file and line on a
// malformed line, a non-finite value, a zero quaternion or a timestamp
// that does not increase. With `line_numbers`, also the 1-based line of
// each pose.
std::vector<TimedPose> ReadTumTrajectory(
    const std::filesystem::path& path,
    std::vector<int>* line_numbers = nullptr);

// Formats poses as TUM lines (with a comment header).
std::string FormatTumTrajectory(const std::vector<TimedPose>& poses,
                                const std::string& comment = "");

// Writes atomically.
void WriteTumTrajectory(const std::filesystem::path& path,
                        const std::vector<TimedPose>& poses,
                        const std::string& comment = "");

// Parses "tx ty tz qx qy qz qw" (a pose on the command line). Throws
// InputError mentioning `what` if malformed.
Rigid3d ParsePose(const std::string& text, const std::string& what);

// Pose at time t by interpolation between the two poses around it. Returns
// false if t is outside the trajectory or the bracketing poses are more
// than max_gap seconds apart.
bool InterpolatePose(const std::vector<TimedPose>& poses, double t,
                     double max_gap, Rigid3d* pose);

}  // namespace monomap
