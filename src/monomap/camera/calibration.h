// Calibration of the camera from views of a flat checkerboard
// (cv::calibrateCamera: Zhang's method, then Levenberg-Marquardt on the
// distorted reprojection error of the detected inner corners).
//
// Why in a mapping toolkit: every stage trusts the calibration, and an
// error at the image's rim does not show in a bundle adjustment's
// residuals, it bends the poses instead. desk_vamr_a's shipped calibration
// fits the sequence's own board corners at 0.18 px RMS and a refit does
// better; the effect on localization is in docs/benchmarks.md ("Desk
// localization").
#pragma once

#include <functional>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "monomap/camera/camera.h"

namespace monomap {

struct CalibrationOptions {
  // The board: inner corners along its two axes and the square side (m).
  int inner_corners_x = 9;
  int inner_corners_y = 6;
  double square_m = 0.04;
  // Use every n-th frame: neighbouring frames add little but time.
  int stride = 5;
  // Fewer views with the board found is an error.
  int min_views = 10;
  // Estimate the tangential terms (p1, p2) and k3 as well as k1, k2.
  bool full_distortion = true;
  void Check() const;
};

struct CalibrationReport {
  Camera camera;  // the refitted calibration (image size of the initial one)
  int frames_tried = 0;
  int views = 0;  // frames in which the whole board was found
  // Reprojection RMS (px) of all corners: each view's pose fitted by PnP
  // with the initial calibration, and after the joint fit.
  double initial_rms_px = 0.0;
  double final_rms_px = 0.0;
  // Largest distance of a detected corner from the principal point (px):
  // the calibration is fitted only out to there.
  double max_corner_radius_px = 0.0;
};

// The inner corners of a cols x rows checkerboard in `grey` (8-bit), to
// sub-pixel precision (cv::findChessboardCorners, then cv::cornerSubPix in
// a window of 2 subpix_half_window + 1), in OpenCV's order: row by row,
// starting at one of the board's corners. nullopt if not all are found.
std::optional<std::vector<cv::Point2f>> DetectCheckerboardCorners(
    const cv::Mat& grey, int cols, int rows, int subpix_half_window = 5);

// Calibrates from frames 0, stride, 2 stride, ... < num_frames given by
// `load_grey` (8-bit, of initial.width x initial.height; called from
// several threads), starting from `initial`. Throws StageError if fewer
// than options.min_views show the whole board.
CalibrationReport CalibrateFromCheckerboard(
    const std::function<cv::Mat(int)>& load_grey, int num_frames,
    const Camera& initial, const CalibrationOptions& options);

}  // namespace monomap
