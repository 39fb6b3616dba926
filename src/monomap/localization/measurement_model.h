// Weight of a pose hypothesis from how well the map rendered from it
// matches the live image: zero-mean normalized cross-correlation (NCC)
// over the pixels where the render shows the map, which ignores exposure
// and gain changes, turned into a likelihood exp((ncc - 1) / sigma).
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "monomap/camera/camera.h"
#include "monomap/geometry/rigid3.h"
#include "monomap/rendering/renderer.h"

namespace monomap {

// Turns raw (distorted) live images into small undistorted ones comparable
// with renders of camera.Pinhole().Scaled(w, h). The remap tables are
// computed once.
class LiveImagePreparer {
 public:
  explicit LiveImagePreparer(const Camera& camera);
  // Raw 8-bit grey (or BGR, converted) image of the camera's size ->
  // undistorted full-size grey image.
  cv::Mat Undistort(const cv::Mat& raw) const;
  // Undistorted full-size grey -> w x h with INTER_AREA.
  static cv::Mat Downscale(const cv::Mat& undistorted, int width, int height);
  // The pinhole camera of a w x h prepared image.
  Camera SmallCamera(int width, int height) const {
    return camera_.Pinhole().Scaled(width, height);
  }
  const Camera& camera() const { return camera_; }

 private:
  Camera camera_;
  cv::Mat map_x_, map_y_;  // empty without distortion
  cv::Mat map_xy_, map_frac_;  // the same in fixed point (cv::convertMaps)
};

struct MeasurementOptions {
  // Size of the renders compared with the live image.
  int width = 80;
  int height = 60;
  // Likelihood temperature: log L = (ncc - 1) / sigma. Smaller is sharper.
  double sigma = 0.05;
  // Below this fraction of map pixels in the render the NCC is scaled by
  // fraction / min_coverage: a pose that sees little map explains little of
  // the image and should not win on a few well-matching pixels.
  double min_coverage = 0.3;
  // Fewer map pixels than this: NCC taken as 0 (log L = -1 / sigma).
  int min_pixels = 20;

  void Check() const;
};

// Result of comparing one render with the live image.
struct MeasurementScore {
  double ncc = 0.0;       // over map pixels, in [-1, 1]
  double coverage = 0.0;  // map pixels / all pixels
  double log_likelihood = 0.0;
};

class MeasurementModel {
 public:
  // `renderer` must outlive the model. `camera` is the live camera.
  MeasurementModel(const Renderer* renderer, const Camera& camera,
                   const MeasurementOptions& options = {});

  // Small undistorted live image (options.width x height) from a raw one.
  cv::Mat PrepareLive(const cv::Mat& raw) const;
  // The same from an already undistorted full-size image.
  cv::Mat PrepareLiveFromUndistorted(const cv::Mat& undistorted) const;

  // Zero-mean NCC of `render` and `live` over pixels with depth > 0.
  static void Ncc(const cv::Mat& render, const cv::Mat& depth,
                  const cv::Mat& live, int min_pixels, double* ncc,
                  double* coverage);
  // Likelihood of a (ncc, coverage) pair.
  double LogLikelihood(double ncc, double coverage) const;

  // Score of one pose against a prepared live image.
  MeasurementScore Score(const cv::Mat& live_small, const Rigid3d& pose) const;
  // Scores of many poses, rendered in parallel (oneTBB).
  std::vector<MeasurementScore> ScoreBatch(
      const cv::Mat& live_small, const std::vector<Rigid3d>& poses) const;

  const LiveImagePreparer& preparer() const { return preparer_; }
  const Camera& render_camera() const { return render_camera_; }
  const MeasurementOptions& options() const { return options_; }

 private:
  const Renderer* renderer_;
  LiveImagePreparer preparer_;
  Camera render_camera_;
  MeasurementOptions options_;
};

}  // namespace monomap
