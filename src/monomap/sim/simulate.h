// The simulator: a robot with a camera and wheel odometry driving through a
// synthetic world, written as a monomap dataset (docs/dataset-format.md)
// with exact ground truth.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include "monomap/camera/camera.h"
#include "monomap/sim/image_synthesis.h"
#include "monomap/sim/robot.h"
#include "monomap/sim/world.h"

namespace monomap {

struct SimulationOptions {
  // World to drive through: one of WorldNames().
  std::string world = "hallway";
  // Seed of the world (its textures) and, unless run_seed is set, of the
  // run too.
  uint64_t seed = 1;
  // Seed of one traversal of the world: odometry errors, exposure variation
  // and image noise. 0: use `seed`. Two runs of the same world differ only
  // in their run_seed (and path options).
  uint64_t run_seed = 0;
  // Number of frames; -1 (or more than the path holds) drives the whole
  // path once.
  int num_frames = -1;
  // Image size; the intrinsics scale with it (same field of view).
  int width = 640;
  int height = 480;
  // Focal length in pixels for a 640-pixel-wide image.
  double focal_px_at_640 = 500.0;
  // Radial distortion (plumb_bob k1, k2): a mild barrel lens.
  double k1 = -0.25;
  double k2 = 0.07;
  // Lens model: "plumb_bob", or "equidistant" (fisheye; k1, k2 are then
  // its first two coefficients, k3 = k4 = 0).
  std::string lens = "plumb_bob";
  // Texture resolution of the world (texels per metre).
  double texture_pixels_per_meter = kDefaultWorldPixelsPerMeter;
  // Robot motion (including start and lateral offsets), camera mount and
  // odometry errors.
  RobotPathOptions path;
  CameraMountOptions mount;
  // Uneven floor: the base rolls and pitches smoothly along the path, each
  // by up to about this much (degrees; two sinusoids over the distance
  // driven, 1.3 and 0.45 m long, phases from run_seed). The planar
  // odometry does not see it; 0: a flat floor.
  double floor_tilt_deg = 0.0;
  OdometryNoiseOptions odometry;
  // Rendering and camera effects.
  RenderOptions render;
  CameraEffectsOptions effects;
  // A textured disc crossing the view (not part of the structure) during
  // [start, start + duration] as fractions of the sequence.
  bool moving_object = false;
  double moving_object_start_fraction = 0.4;
  double moving_object_duration_fraction = 0.2;
  // Disc radius and distance in front of the camera (m).
  double moving_object_radius_m = 0.25;
  double moving_object_distance_m = 1.2;
  // Specular reflections of the ceiling lights sweeping over the floor.
  bool specular_highlight = false;
  // Peak brightness (grey levels) and radius (m) of a highlight.
  double highlight_strength = 120.0;
  double highlight_radius_m = 0.2;
  // Also write the ground-truth structure as a map directory
  // (out_dir/structure/, see io/map_format.h).
  bool write_structure = true;
  // Draw a progress bar on stderr.
  bool show_progress = false;

  void Check() const;
};

struct SimulationReport {
  std::string world;
  int frames = 0;
  int planes = 0;
  double path_length_m = 0.0;
  // Final position error of odometry2d against ground truth.
  double final_drift_m = 0.0;
  double final_drift_percent = 0.0;
  // Final heading error of the odometry (degrees).
  double final_yaw_error_deg = 0.0;
  // Frames showing the moving object: [first, last], -1 if none.
  int moving_object_first_frame = -1;
  int moving_object_last_frame = -1;
  double texture_megabytes = 0.0;
  double seconds = 0.0;
};

// The simulated camera for the options (plumb_bob, centred principal point).
Camera MakeSimulationCamera(const SimulationOptions& options);

// Writes the dataset into out_dir (replacing it atomically: a failure
// leaves the previous content or nothing): rgb/NNNNNN.png, rgb.txt,
// camera.yaml, odometry.txt, odometry2d.txt, camera_mount.yaml,
// groundtruth.txt and structure/ (the world planes as a map). The output
// is byte-identical for the same options.
SimulationReport Simulate(const SimulationOptions& options,
                          const std::filesystem::path& out_dir);

}  // namespace monomap
