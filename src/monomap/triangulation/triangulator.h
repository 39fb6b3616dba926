// Stage 2a of map building: triangulation of KLT tracks with known camera
// poses (from odometry) and calibrated intrinsics.
//
// Per track: linear (DLT) triangulation on undistorted normalized
// coordinates, then Levenberg-Marquardt refinement of the 3D point that
// minimises the reprojection error in raw (distorted) pixels, then the
// acceptance tests (depth/cheirality, triangulation angle, reprojection
// error). Tracks are independent, so they are processed in parallel; the
// output keeps the order of the input tracks.
#pragma once

#include <cstdint>
#include <vector>

#include "monomap/camera/camera.h"
#include "monomap/geometry/rigid3.h"
#include "monomap/map/map.h"

namespace monomap {

struct TriangulationOptions {
  // Tracks with fewer observations are not triangulated: two views give no
  // redundancy to detect a bad KLT match.
  int min_track_length = 3;
  // Largest mean reprojection error (raw pixels) of an accepted point.
  double max_reprojection_error_px = 2.0;
  // Largest reprojection error (raw pixels) of any single observation of an
  // accepted point: catches tracks that jump to another feature for a few
  // frames, which the mean would dilute over a long track.
  double max_observation_error_px = 4.0;
  // Smallest largest-angle (degrees) between viewing rays: below it the depth
  // is poorly conditioned.
  double min_triangulation_angle_deg = 1.5;
  // Smallest depth (m) in every observing camera; also rejects points
  // behind a camera (cheirality).
  double min_depth_m = 0.01;
  // Largest depth (m) in any observing camera: far points carry no useful
  // geometry for a desk-sized map and are mostly wrong.
  double max_depth_m = 100.0;
  // Refine the linear estimate by minimising the pixel reprojection error.
  bool nonlinear_refinement = true;
  // Largest Levenberg-Marquardt iterations of the refinement.
  int max_refinement_iterations = 20;
  // Refinement stops when the point moves less than this fraction of its
  // distance to the first camera.
  double refinement_tolerance = 1e-10;
  // Throws OptionsError naming the field if a value makes no sense.
  void Check() const;
};

struct TriangulationReport {
  int num_tracks = 0;               // tracks given
  int num_points = 0;               // landmarks produced
  int rejected_short = 0;           // fewer than min_track_length observations
  int rejected_failed = 0;          // linear system degenerate / not finite
  int rejected_cheirality = 0;      // depth outside [min_depth, max_depth]
  int rejected_angle = 0;           // triangulation angle too small
  int rejected_reprojection = 0;    // reprojection error too large
  double mean_reprojection_error_px = 0.0;    // over accepted points
  double median_reprojection_error_px = 0.0;  // of per-point mean errors
  double seconds = 0.0;
};

// Triangulates `tracks` (raw pixels) seen from cameras world_from_cam[frame].
// Replaces *landmarks with one landmark per accepted track, in track order,
// color left zero. Throws InputError if an observation's frame has no pose,
// OptionsError for bad options.
TriangulationReport TriangulateTracks(const Camera& camera,
                                      const std::vector<Rigid3d>& world_from_cam,
                                      const std::vector<Track>& tracks,
                                      const TriangulationOptions& options,
                                      std::vector<Landmark>* landmarks);

// Statistics of one point against its observations, shared with bundle
// adjustment so both stages judge points the same way.
struct PointStatistics {
  double mean_error_px = 0.0;
  double max_error_px = 0.0;
  double min_depth_m = 0.0;  // smallest z over the observing cameras
  double max_depth_m = 0.0;  // largest z over the observing cameras
  double mean_distance_m = 0.0;  // mean distance to the camera centres
  double triangulation_angle_deg = 0.0;
  // Covariance of the point for 1 px observation noise (see
  // Landmark::covariance_m2_per_px2); zero if the geometry does not fix it.
  Eigen::Matrix3d covariance_m2_per_px2 = Eigen::Matrix3d::Zero();
};

// Evaluates x_in_world against a track's observations; cams_from_world is
// indexed by frame. Reprojection errors are in raw pixels; an observation in
// a camera where the point has z <= 0 counts as infinite error.
PointStatistics EvaluatePoint(const Camera& camera,
                              const std::vector<Rigid3d>& cams_from_world,
                              const Track& track,
                              const Eigen::Vector3d& x_in_world);

// Moves x_in_world to minimise the reprojection error (raw px) of `track`
// with the poses fixed (Levenberg-Marquardt, options.max_refinement_iterations
// and options.refinement_tolerance). cams_from_world is indexed by frame.
// Leaves x_in_world unchanged if it is behind one of the cameras.
void RefinePoint(const Camera& camera,
                 const std::vector<Rigid3d>& cams_from_world,
                 const Track& track, const TriangulationOptions& options,
                 Eigen::Vector3d* x_in_world);

// Copy of `tracks` without the observations farther than max_radius_px
// from the principal point (raw pixels); tracks left empty are dropped.
// Why: a calibration is only known where its views put their corners (a
// checkerboard seldom reaches the image's corners); beyond, its
// distortion polynomial extrapolates, and bundle adjustment bends the
// poses to fit it while the residuals stay at the noise. *dropped (if
// given) receives the number of observations removed.
std::vector<Track> ObservationsWithinRadius(const std::vector<Track>& tracks,
                                            const Camera& camera,
                                            double max_radius_px,
                                            int64_t* dropped = nullptr);

}  // namespace monomap
