// A second ground truth from the images themselves: the camera pose of
// every frame that shows a known checkerboard, by PnP on its detected inner
// corners (Levenberg-Marquardt on the distorted reprojection error).
//
// Why: a dataset's ground truth is itself an estimate. On desk_vamr_a the
// shipped groundtruth.txt reprojects the board corners at 0.21 px (median)
// where the least-squares pose reaches 0.12 px, and differs from it by a
// nearly constant 0.17 deg. Comparing a trajectory with both tells the
// ground truth's own error apart from the estimate's.
#pragma once

#include <functional>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "monomap/camera/camera.h"
#include "monomap/eval/checkerboard_accuracy.h"
#include "monomap/eval/point_accuracy.h"
#include "monomap/geometry/rigid3.h"
#include "monomap/map/map.h"

namespace monomap {

struct BoardPoseOptions {
  // A pose whose RMS reprojection error over the corners exceeds this (px)
  // is refused (a blurred or partly hidden board).
  double max_rms_px = 1.0;
  // Half side (px) of cv::cornerSubPix's search window.
  int subpix_half_window = 5;
  void Check() const;
};

// The board pose of one image.
struct BoardPose {
  Rigid3d world_from_cam;
  // RMS and median reprojection error of the corners (px).
  double rms_px = 0.0;
  double median_px = 0.0;
  // Formal standard deviations from the PnP Jacobian and the residuals:
  // largest over the axes, rotation in degrees, camera centre in metres.
  double rotation_sigma_deg = 0.0;
  double position_sigma_m = 0.0;
};

// Detects the board in `grey` (8-bit, raw distorted image of `camera`) and
// estimates world_from_cam. A board with an even symmetry (any board, seen
// from the front, maps onto itself by a half turn) leaves the corner order
// ambiguous; of the orderings that fit, the pose closest in rotation to
// `hint_world_from_cam` is taken (odometry is close enough: it only has to
// tell a half turn apart). Returns nullopt if the board is not found or the
// fit is worse than max_rms_px.
std::optional<BoardPose> EstimateBoardPose(const cv::Mat& grey,
                                           const Camera& camera,
                                           const CheckerboardSpec& spec,
                                           const Rigid3d& hint_world_from_cam,
                                           const BoardPoseOptions& options);

struct BoardPoseReport {
  int frames = 0;
  // Frames with a pose, in frame order.
  std::vector<TimedPose> poses;
  ErrorStats rms_px;
  ErrorStats rotation_sigma_deg;
  ErrorStats position_sigma_m;
};

// EstimateBoardPose over frames 0 .. num_frames-1 in parallel (oneTBB).
// `load_grey(i)` must be thread-safe; `timestamps` and `hints` have
// num_frames entries.
BoardPoseReport EstimateBoardPoses(const std::function<cv::Mat(int)>& load_grey,
                                   const std::vector<double>& timestamps,
                                   const std::vector<Rigid3d>& hints,
                                   const Camera& camera,
                                   const CheckerboardSpec& spec,
                                   const BoardPoseOptions& options);

// Re-expresses `poses` (board world) in another frame, e.g. the odometry a
// map was built in: `anchor_world_from_cam` is the first pose's camera in
// that frame; the same change of frame applies to every pose.
void ExpressInAnchorFrame(const Rigid3d& anchor_world_from_cam,
                          std::vector<TimedPose>* poses);

}  // namespace monomap
