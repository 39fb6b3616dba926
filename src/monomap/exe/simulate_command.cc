// monomap simulate WORLD -o DATASET_DIR [--seed N] [--run-seed N]
//   [--frames N] [--start-offset M] [--lateral-offset M] ...
//
// The options bind to a default-constructed SimulationOptions, so `--help`
// shows the library's defaults.
#include <cstdio>
#include <memory>

#include "monomap/exe/commands.h"
#include "monomap/sim/simulate.h"
#include "monomap/sim/world.h"
#include "monomap/util/file.h"

namespace monomap {

namespace {

// Seeds and where along the path the run goes.
void AddRunOptions(CLI::App* cmd, SimulationOptions* o) {
  cmd->add_option("--seed", o->seed,
                  "Seed of the world (textures) and, without --run-seed, of "
                  "the run")
      ->capture_default_str();
  cmd->add_option("--run-seed", o->run_seed,
                  "Seed of this traversal: odometry errors, exposure and "
                  "image noise (0: --seed)")
      ->capture_default_str();
  cmd->add_option("--start-offset", o->path.start_offset_m,
                  "Start this far along the path (m)")
      ->capture_default_str();
  cmd->add_option("--lateral-offset", o->path.lateral_offset_m,
                  "Drive parallel to the path, this far to the left (m)")
      ->capture_default_str();
  cmd->add_option("--frames", o->num_frames,
                  "Number of frames (-1: the whole path)")
      ->capture_default_str();
}

// The image, the camera and how it is mounted.
void AddCameraOptions(CLI::App* cmd, SimulationOptions* o) {
  cmd->add_option("--width", o->width, "Image width")->capture_default_str();
  cmd->add_option("--height", o->height, "Image height")->capture_default_str();
  cmd->add_option("--speed", o->path.speed_mps, "Robot speed (m/s)")
      ->capture_default_str();
  cmd->add_option("--fps", o->path.rate_hz, "Camera and odometry rate (Hz)")
      ->capture_default_str();
  cmd->add_option("--camera-height", o->mount.height_m,
                  "Height of the camera above the floor (m)")
      ->capture_default_str();
  cmd->add_option("--camera-tilt", o->mount.tilt_down_deg,
                  "Downward pitch of the camera (degrees)")
      ->capture_default_str();
  cmd->add_option("--floor-tilt", o->floor_tilt_deg,
                  "Uneven floor: the base rolls and pitches by up to about "
                  "this much (degrees), unseen by the planar odometry")
      ->check(CLI::Range(0.0, 10.0))
      ->capture_default_str();
  cmd->add_option("--focal", o->focal_px_at_640,
                  "Focal length (pixels, for a 640-pixel-wide image)")
      ->capture_default_str();
  cmd->add_option("--k1", o->k1, "Radial distortion k1 (plumb_bob)")
      ->capture_default_str();
  cmd->add_option("--k2", o->k2, "Radial distortion k2 (plumb_bob)")
      ->capture_default_str();
}

// The errors of the simulated wheel odometry.
void AddOdometryOptions(CLI::App* cmd, SimulationOptions* o) {
  cmd->add_option("--odometry-scale-error", o->odometry.wheel_radius_error,
                  "Systematic wheel radius error (fraction)")
      ->capture_default_str();
  cmd->add_option("--odometry-yaw-error", o->odometry.yaw_scale_error,
                  "Systematic yaw scale error (fraction)")
      ->capture_default_str();
  cmd->add_option("--odometry-translation-noise", o->odometry.translation_noise,
                  "Random translation noise (fraction of each step)")
      ->capture_default_str();
  cmd->add_option("--odometry-rotation-noise",
                  o->odometry.rotation_noise_per_meter,
                  "Random rotation noise (rad per metre)")
      ->capture_default_str();
  cmd->add_option("--odometry-seed", o->odometry.seed,
                  "Seed of the odometry errors")
      ->capture_default_str();
}

}  // namespace

void RegisterSimulateCommand(CLI::App& app) {
  auto o = std::make_shared<SimulationOptions>();
  auto out = std::make_shared<std::string>();
  auto quiet = std::make_shared<bool>(false);
  CLI::App* cmd = app.add_subcommand(
      "simulate",
      "Generate a synthetic dataset with exact ground truth (worlds: " +
          [] {
            std::string s;
            for (const auto& n : WorldNames()) s += (s.empty() ? "" : ", ") + n;
            return s;
          }() +
          ")");
  cmd->add_option("world", o->world, "World name")->required();
  cmd->add_option("-o,--output", *out, "Dataset directory to write")
      ->required();
  AddRunOptions(cmd, o.get());
  AddCameraOptions(cmd, o.get());
  AddOdometryOptions(cmd, o.get());
  cmd->add_flag("--moving-object", o->moving_object,
                "Add an object crossing the view");
  cmd->add_flag("--highlight", o->specular_highlight,
                "Add specular highlights sweeping over the floor");
  cmd->add_flag("-q,--quiet", *quiet, "No progress output");
  cmd->callback([o, out, quiet]() {
    CheckOutputDirectory(*out, "dataset", {});
    o->show_progress = !*quiet;
    const SimulationReport r = Simulate(*o, *out);
    if (!*quiet) {
      std::fprintf(stderr,
                   "monomap: %s: %d frames, %d planes, path %.2f m, "
                   "odometry drift %.3f m (%.2f%%) in %.1f s -> %s\n",
                   r.world.c_str(), r.frames, r.planes, r.path_length_m,
                   r.final_drift_m, r.final_drift_percent, r.seconds,
                   out->c_str());
    }
  });
}

}  // namespace monomap
