// Monte Carlo Correction: moves a particle onto the pose the live image
// supports. The map is rendered (with depth) from the particle's pose,
// corners of the render are tracked into the live image with pyramidal
// KLT, each tracked corner has a 3D point from the render depth, and the
// 3D-2D matches give a corrected pose by PnP (RANSAC, then Levenberg-
// Marquardt on the inliers, started from the particle's pose).
#pragma once

#include <opencv2/core.hpp>

#include "monomap/camera/camera.h"
#include "monomap/geometry/rigid3.h"
#include "monomap/rendering/renderer.h"

namespace monomap {

struct MccOptions {
  // Size of the render and of the live image compared with it.
  int width = 160;
  int height = 120;
  // Corners detected in the render (cv::goodFeaturesToTrack).
  int max_corners = 200;
  double corner_quality = 0.01;
  double min_corner_distance_px = 3.0;
  // Corners closer than this to the map's silhouette are skipped: their
  // neighbourhood mixes map and background.
  int border_px = 4;
  // KLT window side and pyramid levels above the base. Few levels and a
  // small window: at 160x120 the top of a 3-level pyramid is 20x15 px, its
  // windows span the map's silhouette against the background, and most
  // tracks run off (docs/design-notes.md, "Localization"; bench/mcc_basin).
  int klt_window = 11;
  int klt_levels = 1;
  // Forward-backward KLT check: largest round-trip error (px).
  double max_forward_backward_px = 0.5;
  // RANSAC inlier threshold of PnP (px) and iterations.
  double ransac_threshold_px = 1.5;
  int ransac_iterations = 100;
  // A correction needs this many inliers...
  int min_inliers = 15;
  // ... and may move the pose at most this far (m, degrees): the basin
  // reaches 20-30 cm, and the inlier fit (rms <= ransac_threshold_px)
  // guards against wrong matches. 20 deg rather than 10 lets MCC recover
  // particles near the truth but well off in heading after a kidnapping
  // (docs/design-notes.md, "Localization").
  double max_translation_m = 0.5;
  double max_rotation_deg = 20.0;
  // Added to the renderer's mip bias for the renders tracked here: half a
  // level blurrier tames aliasing along oblique views, which KLT minds more
  // than the weights do (docs/design-notes.md, "Localization").
  double extra_mip_bias = 0.5;
  // Render-track-solve rounds; the second one starts from an almost
  // aligned render and removes most of the first round's bias.
  int iterations = 2;
  // A round that moved the inliers' projections by less than this (RMS,
  // px) started from an aligned render already: the next round would
  // repeat it, so the correction stops. 0: always all iterations.
  double converged_px = 0.0;

  void Check() const;
};

// What one correction did.
struct MccResult {
  bool accepted = false;
  Rigid3d world_from_cam;  // corrected pose (input pose if not accepted)
  int corners = 0;         // detected in the (last) render
  int tracked = 0;         // passed the forward-backward check
  int inliers = 0;         // PnP inliers
  double rms_reprojection_px = 0.0;  // over inliers, at options' size
  double shift_px = 0.0;  // RMS move of the inliers' projections (last round)
  int rounds = 0;         // render-track-solve rounds run
  double translation_change_m = 0.0;
  double rotation_change_deg = 0.0;
};

class MonteCarloCorrector {
 public:
  // `camera` is the live camera; the corrector keeps a copy of `renderer`
  // that shares its pyramids.
  MonteCarloCorrector(const Renderer* renderer, const Camera& camera,
                      const MccOptions& options = {});

  // `live` is the undistorted live image downscaled to options.width x
  // height (LiveImagePreparer). Thread-safe.
  MccResult Correct(const cv::Mat& live, const Rigid3d& world_from_cam) const;

  const Camera& render_camera() const { return render_camera_; }
  const MccOptions& options() const { return options_; }

 private:
  // One render-track-solve round; false if it found too little.
  bool Round(const cv::Mat& live, const Rigid3d& start, Rigid3d* out,
             MccResult* stats) const;

  Renderer renderer_;  // the caller's, with options.extra_mip_bias
  Camera render_camera_;
  MccOptions options_;
};

}  // namespace monomap
