// Stage 4: plane-induced homographies between each image and each plane it
// sees, checked (and if needed corrected) against the tracked features that
// lie on the plane.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "monomap/camera/camera.h"
#include "monomap/geometry/rigid3.h"
#include "monomap/map/map.h"

namespace monomap {

struct HomographyOptions {
  // Side of the grid of polygon samples used to decide whether a frame sees
  // a plane (samples = grid points inside the polygon).
  int visibility_grid = 12;
  // A frame sees a plane if at least this fraction of the polygon samples
  // projects into the image, in front of the camera.
  double min_visible_fraction = 0.02;
  // Points closer than this to the camera centre (m) count as not visible:
  // the projection is meaningless behind or at the camera.
  double min_depth_m = 0.01;
  // Features that check (and refine) a homography: those whose landmark
  // projects within this many pixels of its projection onto the plane, so
  // that parallax of points off the plane (within the plane fit's band) is
  // not taken for a homography error: refining on that parallax registers
  // the texture to the features instead of the poses (design-notes.md,
  // "Homographies and texture").
  double max_feature_parallax_px = 0.5;
  // Refine when the median feature residual exceeds this (pixels).
  double refine_threshold_px = 1.0;
  // Refine only with at least this many features of the plane in the frame.
  int min_features_to_refine = 8;
  // RANSAC inlier threshold of the correction homography (pixels).
  double ransac_threshold_px = 2.0;
  // A correction may move no polygon corner by more than this (pixels): a
  // homography fitted to a few clustered features extrapolates badly.
  double max_corner_shift_px = 25.0;
  // Allow refinement at all (false: pose-induced homographies only).
  bool refine = true;

  void Check() const;
};

// Residual statistics of features, in pixels.
struct ResidualStats {
  double mean = 0.0;
  double median = 0.0;
  double max = 0.0;
};

struct ImagePlaneHomography {
  int frame = 0;
  int plane_id = 0;  // PlaneSegment::id
  // Plane coordinates (s, t, 1) of the segment's PlaneFrame -> undistorted
  // pinhole pixels K (x/z, y/z, 1).
  Eigen::Matrix3d pixel_from_plane = Eigen::Matrix3d::Identity();
  // Plane features observed in this frame that check the homography (see
  // HomographyOptions::max_feature_parallax_px).
  int num_features = 0;
  // Median feature residual (pixels) of the pose-induced homography and of
  // the one kept (equal unless refined). 0 without features.
  double residual_before_px = 0.0;
  double residual_after_px = 0.0;
  ResidualStats before;  // mean / median / max before refinement
  ResidualStats after;   // mean / median / max of the kept homography
  bool refined = false;
  // Fraction of the polygon samples visible in the image.
  double visible_fraction = 0.0;
  // Image resolution of the plane at the polygon centre: sqrt(|det J|) of
  // the homography, pixels per metre (geometric mean of both directions).
  double pixels_per_meter = 0.0;
};

struct HomographyReport {
  int num_homographies = 0;
  int num_checked = 0;   // with at least one feature observation
  int num_refined = 0;   // corrections kept
  int num_refinement_rejected = 0;  // attempted but not kept
  double median_residual_before_px = 0.0;  // over checked homographies
  double median_residual_after_px = 0.0;
  double seconds = 0.0;
};

// Undistorted pinhole pixel of a raw (distorted) pixel.
Eigen::Vector2d UndistortedPixel(const Camera& camera,
                                 const Eigen::Vector2d& raw_px);

// Image resolution (pixels per metre, sqrt(|det J|)) of the homography h
// at plane point st; 0 if st maps to infinity.
double HomographyPixelsPerMeter(const Eigen::Matrix3d& h,
                                const Eigen::Vector2d& st);

// One ImagePlaneHomography per (frame, plane) pair in which the frame sees
// the plane, sorted by frame then plane order. Plane features are the
// segment's inlier_ids plus the landmarks whose plane_id is the segment id;
// their observations come from `tracks` (matched by id).
HomographyReport ComputeImagePlaneHomographies(
    const Camera& camera, const std::vector<Rigid3d>& world_from_cam,
    const std::vector<PlaneSegment>& segments,
    const std::vector<Landmark>& landmarks, const std::vector<Track>& tracks,
    const HomographyOptions& options,
    std::vector<ImagePlaneHomography>* homographies);

}  // namespace monomap
