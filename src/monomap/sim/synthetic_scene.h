// Synthetic track/pose scenes with known truth, for the triangulation and
// evaluation tests and benchmarks: a camera sliding sideways in front of
// random points, KLT-like tracks of raw distorted pixels, and odometry with
// a realistic drift. (Textured-plane scenes: textured_plane_scene.h; the
// localization room: room_scene.h.)
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "monomap/camera/camera.h"
#include "monomap/geometry/rigid3.h"
#include "monomap/map/map.h"

namespace monomap {

struct SyntheticSceneOptions {
  // Frames of the trajectory.
  int num_frames = 60;
  // Camera travel per frame (m), sideways along world x.
  double step_m = 0.003;
  // Tracks (one 3D point each).
  int num_tracks = 500;
  // Track length, uniform in [min, max] frames (clipped at the sequence).
  int min_track_length = 10;
  int max_track_length = 50;
  // Depth (m) of a point in the camera at the middle of its track.
  double min_depth_m = 0.3;
  double max_depth_m = 0.6;
  // Gaussian noise (px, per axis) on the observations.
  double pixel_noise_px = 0.0;
  uint64_t seed = 1;
  // The camera; empty: SyntheticCamera().
  std::optional<Camera> camera;
};

struct SyntheticScene {
  Camera camera;                         // options.camera or SyntheticCamera()
  std::vector<Rigid3d> world_from_cam;   // truth, one per frame
  std::vector<Eigen::Vector3d> points;   // truth, points[i] for tracks[i]
  std::vector<Track> tracks;             // tracks[i].id == i
};

// The plumb_bob test camera: 752x480, f=420, k1=-0.3, k2=0.08, small
// tangential terms.
Camera SyntheticCamera();

SyntheticScene MakeSyntheticScene(const SyntheticSceneOptions& options);

struct OdometryDriftOptions {
  // Random walk: per-axis Gaussian translation noise per step, as a
  // fraction of the step length.
  double translation_noise_fraction = 0.05;
  // Relative scale error of every step.
  double scale_error = 0.005;
  // Systematic rotation drift (degrees per metre travelled) about a fixed
  // axis, plus per-axis Gaussian rotation noise per frame (degrees).
  double rotation_drift_deg_per_m = 1.0;
  double rotation_noise_deg = 0.01;
  uint64_t seed = 2;
};

// Odometry as it would come from a drifting sensor: anchored at the first
// true pose, each relative motion corrupted as described by the options.
std::vector<Rigid3d> SimulateOdometryDrift(
    const std::vector<Rigid3d>& world_from_cam,
    const OdometryDriftOptions& options);

}  // namespace monomap
