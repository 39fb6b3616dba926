// Writes a dataset in monomap's layout (docs/dataset-format.md) from data
// an importer gathered: the importers (ROS bag, TUM RGB-D, ...) put their
// images into the directory themselves and hand over the rest here.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "monomap/camera/camera.h"
#include "monomap/io/dataset.h"

namespace monomap {

struct ImportedFrame {
  double timestamp = 0.0;
  // Image path relative to the dataset root, e.g. "rgb/000012.png".
  std::string image;
  Rigid3d odometry_world_from_cam;
  // Planar base pose; written to odometry2d.txt only if every frame has one
  // (and a mount is given).
  std::optional<Pose2d> odometry_base;
  // Written to groundtruth.txt only if every frame has one.
  std::optional<Rigid3d> groundtruth_world_from_cam;
};

// Writes camera.yaml, rgb.txt, odometry.txt and, as they apply,
// odometry2d.txt + camera_mount.yaml and groundtruth.txt into `dir`.
// `source` goes into the files' comment headers. Throws InputError if
// `frames` is empty or the timestamps do not increase.
void WriteImportedDataset(const std::filesystem::path& dir,
                          const Camera& camera,
                          const std::vector<ImportedFrame>& frames,
                          const std::optional<Rigid3d>& base_from_cam,
                          const std::string& source);

// Planar pose (x, y, yaw) of a base pose whose z axis is vertical, or
// nullopt if the base tilts more than max_tilt_rad or is lifted more than
// max_height_m off the floor (then only 6-DoF odometry is written).
std::optional<Pose2d> PlanarPose(const Rigid3d& world_from_base,
                                 double max_tilt_rad, double max_height_m);

}  // namespace monomap
