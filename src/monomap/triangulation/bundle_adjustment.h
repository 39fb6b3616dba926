// Stage 2b of map building: bundle adjustment of the camera poses and the
// triangulated landmarks, correcting odometry drift.
//
// Residuals:
//  * reprojection error in raw (distorted) pixels: the plumb_bob distortion
//    is applied inside the templated cost, so the error is measured where
//    the KLT noise lives; under a robust loss (Huber or Cauchy);
//  * a prior between consecutive frames on the relative motion
//    cam_i_from_cam_{i+1} of the ORIGINAL odometry, weighted by sigmas that
//    grow with the step length. A monocular camera cannot observe scale: the
//    priors keep it (and keep unobserved frames in place);
//  * for a wheeled base (the dataset gives the camera mount), a prior per
//    pose that the base stays level and at its height on the floor: the
//    relative priors let tilt drift like any rotation, and mistracked
//    observations (edges, occlusion boundaries) pull it.
// The first pose is held fixed (the odometry is anchored at it), which fixes
// the gauge. The lens is held fixed, unless refine_distortion (all five
// distortion coefficients, no prior) or intrinsics.enabled (focal length,
// principal point, k1, k2 under a prior, trusted only where the data
// constrain them: intrinsics_refinement.h) is set.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "monomap/camera/camera.h"
#include "monomap/geometry/rigid3.h"
#include "monomap/map/map.h"
#include "monomap/triangulation/intrinsics_refinement.h"

namespace monomap {

// Prior of a wheeled robot on a flat floor: its base keeps the tilt and
// height the (planar) odometry gives it, within these sigmas.
struct PlanarBaseOptions {
  // Use it when base_from_cam is set.
  bool enabled = true;
  // The camera mount (camera pose in the base frame); the pipeline sets it
  // from the dataset's camera_mount.yaml. Unset: no planar prior.
  std::optional<Rigid3d> base_from_cam;
  // Sigma of the base's roll and pitch (degrees), per pose: floors, thresholds
  // and suspension tilt a real base a little.
  double tilt_sigma_deg = 0.2;
  // Sigma of the base's height (m), per pose.
  double height_sigma_m = 0.005;
  void Check() const;
};

struct BundleAdjustmentOptions {
  // Off: poses and landmarks are returned unchanged (the report still
  // gives the reprojection error).
  bool enabled = true;
  // Robust loss of the reprojection residuals: "huber", "cauchy" or
  // "none".
  std::string loss = "huber";
  // Scale (px) of the robust loss: residuals beyond it are down-weighted.
  double loss_scale_px = 1.0;
  // After the first solve, observations whose reprojection error (raw px)
  // exceeds this leave the problem and it is solved again: the robust loss
  // still lets mistracked observations pull the poses linearly (0: one
  // solve; figures: docs/design-notes.md, "Bundle adjustment and
  // calibration").
  double outlier_threshold_px = 2.0;
  // Odometry prior, translation sigma per step (per axis): this fraction of
  // the step length ...
  double translation_sigma_fraction = 0.05;
  // ... plus this floor (m), so standing still is not infinitely certain.
  double translation_sigma_floor_m = 0.0002;
  // Odometry prior, rotation sigma per step (per axis, degrees): this
  // floor ...
  double rotation_sigma_floor_deg = 0.02;
  // ... plus this much per metre travelled in the step.
  double rotation_sigma_deg_per_m = 1.0;
  // Odometry prior over longer spans: between poses i and i + span_poses of
  // the adjustment (keyframes, when the pipeline adjusts keyframes), for
  // every i; 0: off. The per-step priors model the odometry's error as
  // accumulating increments; for an odometry whose error is per-frame
  // jitter, span priors hold the drift while loosened per-step priors let
  // the images set the motion (figures: docs/design-notes.md, "Bundle adjustment and calibration").
  int span_poses = 0;
  // Rotation sigma of a span prior (per axis, degrees). Fixed, not grown
  // with the span's length: set it to the drift expected over a span.
  double span_rotation_sigma_deg = 0.08;
  // Translation sigma of a span prior (per axis): this fraction of the
  // span's odometry translation, plus translation_sigma_floor_m.
  double span_translation_sigma_fraction = 0.05;
  // Planar-base prior (a wheeled robot's camera).
  PlanarBaseOptions planar_base;
  // Refine the distortion coefficients (k1, k2, p1, p2, k3) with the poses
  // and points, for a calibration that is off at the image's rim. Off by
  // default: it straightens the trajectory but moves the structure; a
  // calibration refitted on board views (`monomap calibrate`) is the better
  // fix (figures: docs/design-notes.md).
  bool refine_distortion = false;
  // Lens self-calibration (focal, principal point, k1, k2) under a prior;
  // exclusive with refine_distortion.
  IntrinsicsRefinementOptions intrinsics;
  // Hold the first pose fixed (gauge). If false, the first pose gets an
  // absolute prior with the floor sigmas instead.
  bool fix_first_pose = true;
  // Most landmarks in the joint adjustment (0: all). The poses need only a
  // few thousand well-spread points; the cost grows with every point times
  // its track length squared. The longest tracks are taken, spread evenly
  // over the frames; the other landmarks are then refined one by one with
  // the adjusted poses held fixed.
  int max_points = 3000;
  // Largest Levenberg-Marquardt iterations.
  int max_num_iterations = 50;
  // Ceres stops when the relative cost decrease is below this: the cost
  // flattens after a few iterations on drifting odometry, and a tighter
  // value costs iterations that move poses by micrometres.
  double function_tolerance = 1e-4;
  // Threads Ceres uses for Jacobians and the linear solver.
  int num_threads = 1;
  // Up to this many poses the reduced camera system is solved densely
  // (DENSE_SCHUR), which is faster while it is small. Beyond, the
  // block-sparse solver: the system is banded (tracks span tens of frames),
  // so its cost grows linearly with the sequence, the dense one's cubically
  // (timings: docs/benchmarks.md).
  int dense_schur_max_poses = 150;
  // Always use ITERATIVE_SCHUR (preconditioned CG): for very long
  // sequences where the reduced camera system gets large.
  bool iterative_schur = false;
  // ... and use it instead of DENSE_SCHUR when the adjusted points are
  // seen by more than this many frames on average over their observations
  // (sum k^2 / sum k for points seen k times): forming the dense Schur
  // complement costs a 6x6 block product per pair of observations of a
  // point, a CG iteration one per observation (timings:
  // docs/benchmarks.md). <= 0: never.
  double iterative_schur_min_covisibility = 40.0;
  // CG stops when its residual falls below this fraction of the right-hand
  // side (Ceres' eta). Ceres' default 0.1 leaves the weakly constrained
  // directions (scale, held by the priors alone) unconverged; 1e-3 reaches
  // the direct solvers' solution (docs/design-notes.md).
  double iterative_schur_eta = 1e-3;
  // After adjustment, landmarks whose mean reprojection error (raw px)
  // exceeds this are dropped (same meaning and default as
  // TriangulationOptions::max_reprojection_error_px).
  double max_reprojection_error_px = 2.0;
  // Landmarks closer than this (m) to any observing camera, or behind it,
  // after adjustment are dropped (as TriangulationOptions::min_depth_m).
  double min_depth_m = 0.01;
  // Print Ceres' per-iteration progress and full report to stdout.
  bool verbose = false;
  // Throws OptionsError naming the field if a value makes no sense.
  void Check() const;
};

struct BundleAdjustmentReport {
  int num_poses = 0;         // pose blocks in the problem
  int num_points = 0;        // landmarks given
  int num_points_joint = 0;  // of which in the joint adjustment
  int num_residuals = 0;     // reprojection residual blocks (observations)
  int num_priors = 0;        // odometry prior residual blocks (per step)
  int num_span_priors = 0;   // odometry priors over span_poses
  int num_planar_priors = 0;  // planar-base priors (one per pose)
  // Observations taken out after the first solve (outlier_threshold_px),
  // and landmarks that left the joint problem with them (fewer than two
  // observations left; refined alone afterwards).
  int num_outlier_observations = 0;
  int num_outlier_points = 0;
  double initial_rms_error_px = 0.0;  // reprojection, all observations
  double final_rms_error_px = 0.0;
  double initial_median_error_px = 0.0;
  double final_median_error_px = 0.0;
  int iterations = 0;
  // Mean number of frames seeing a joint point, over its observations
  // (sum k^2 / sum k), and the linear solver it chose.
  double covisibility = 0.0;
  // Every n-th keyframe was adjusted (BundleAdjustKeyframes' thinning; 1:
  // all of them).
  int keyframe_thinning = 1;
  std::string linear_solver;
  std::string termination;  // Ceres termination type, "disabled" if off
  // Distortion (k1, k2, p1, p2, k3) the final poses and points go with: the
  // camera's, or the refined one.
  std::array<double, 5> distortion = {0, 0, 0, 0, 0};
  // The whole camera the final poses and points go with.
  Camera camera;
  // Lens self-calibration: refined or not, why, before and after.
  IntrinsicsRefinementReport intrinsics;
  int num_dropped = 0;                // landmarks dropped after adjustment
  double mean_pose_change_m = 0.0;    // mean camera centre displacement
  double mean_pose_change_deg = 0.0;  // mean rotation change
  double seconds = 0.0;
};

// Adjusts *world_from_cam (indexed by frame, odometry on input) and
// *landmarks (tracks are matched to landmarks by id; only landmarks passed
// in are adjusted). Landmark fields (error, angle, depth) are updated, and
// landmarks with too large an error afterwards are removed (order of the
// others kept). Throws InputError if a landmark has no track or a track
// refers to a frame without pose, OptionsError for bad options.
BundleAdjustmentReport BundleAdjust(const Camera& camera,
                                    const std::vector<Track>& tracks,
                                    const BundleAdjustmentOptions& options,
                                    std::vector<Rigid3d>* world_from_cam,
                                    std::vector<Landmark>* landmarks);

}  // namespace monomap
