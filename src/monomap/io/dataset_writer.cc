#include "monomap/io/dataset_writer.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "monomap/io/trajectory_io.h"
#include "monomap/util/error.h"
#include "monomap/util/file.h"

namespace monomap {
namespace fs = std::filesystem;

namespace {

// Six decimals, as TUM files print timestamps.
std::string FormatTime(double t) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.6f", t);
  return buf;
}

std::string RgbList(const std::vector<ImportedFrame>& frames,
                    const std::string& source) {
  std::ostringstream out;
  out << "# images imported from " << source << "\n# timestamp filename\n";
  for (const ImportedFrame& f : frames) {
    out << FormatTime(f.timestamp) << " " << f.image << "\n";
  }
  return out.str();
}

std::string Odometry2dList(const std::vector<ImportedFrame>& frames,
                           const std::string& source) {
  std::ostringstream out;
  out.precision(12);
  out << "# planar base odometry imported from " << source
      << "\n# timestamp x y yaw\n";
  for (const ImportedFrame& f : frames) {
    out << FormatTime(f.timestamp) << " " << f.odometry_base->x << " "
        << f.odometry_base->y << " " << f.odometry_base->yaw << "\n";
  }
  return out.str();
}

}  // namespace

std::optional<Pose2d> PlanarPose(const Rigid3d& world_from_base,
                                 double max_tilt_rad, double max_height_m) {
  const Eigen::Vector3d up =
      world_from_base.rotation * Eigen::Vector3d::UnitZ();
  if (std::acos(std::clamp(up.z(), -1.0, 1.0)) > max_tilt_rad) {
    return std::nullopt;
  }
  if (std::abs(world_from_base.translation.z()) > max_height_m) {
    return std::nullopt;
  }
  const Eigen::Vector3d forward =
      world_from_base.rotation * Eigen::Vector3d::UnitX();
  return Pose2d{world_from_base.translation.x(),
                world_from_base.translation.y(),
                std::atan2(forward.y(), forward.x())};
}

void WriteImportedDataset(const fs::path& dir, const Camera& camera,
                          const std::vector<ImportedFrame>& frames,
                          const std::optional<Rigid3d>& base_from_cam,
                          const std::string& source) {
  if (frames.empty()) {
    throw InputError(source + ": no frame left to import");
  }
  for (size_t i = 1; i < frames.size(); ++i) {
    if (frames[i].timestamp <= frames[i - 1].timestamp) {
      throw InputError(source + ": image timestamp " +
                       FormatTime(frames[i].timestamp) +
                       " does not increase (duplicate or unsorted images)");
    }
  }
  WriteCameraYaml(dir / "camera.yaml", camera, "imported");
  WriteFileAtomic(dir / "rgb.txt", RgbList(frames, source));
  std::vector<TimedPose> odometry, groundtruth;
  bool all_planar = base_from_cam.has_value();
  bool all_groundtruth = true;
  for (const ImportedFrame& f : frames) {
    odometry.push_back({f.timestamp, f.odometry_world_from_cam});
    all_planar = all_planar && f.odometry_base.has_value();
    all_groundtruth = all_groundtruth && f.groundtruth_world_from_cam;
    if (f.groundtruth_world_from_cam) {
      groundtruth.push_back({f.timestamp, *f.groundtruth_world_from_cam});
    }
  }
  WriteTumTrajectory(dir / "odometry.txt", odometry,
                     "odometry (world_from_cam) imported from " + source);
  if (all_planar) {
    WriteFileAtomic(dir / "odometry2d.txt", Odometry2dList(frames, source));
    WriteCameraMountYaml(dir / "camera_mount.yaml", *base_from_cam);
  }
  if (all_groundtruth) {
    WriteTumTrajectory(dir / "groundtruth.txt", groundtruth,
                       "ground truth (world_from_cam) from " + source);
  }
}

}  // namespace monomap
