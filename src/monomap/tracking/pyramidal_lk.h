// Pyramidal Lucas-Kanade (cv::calcOpticalFlowPyrLK) over chunks of the
// points in parallel with oneTBB. The points are independent, so the
// result equals one call's; the win is using every core when one image
// pair is tracked at a time (the KLT tracker's serial stage, MCC's
// full-size refinement).
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace monomap {

struct PyrLkOptions {
  // Side of the square search window (px).
  int window = 21;
  // Pyramid levels above the base (0: base only).
  int levels = 3;
  // Iterations and step size (px) at which a level's search stops.
  int max_iterations = 30;
  double epsilon = 0.01;
  // Points whose window's gradient matrix has a smaller minimum eigenvalue
  // (per pixel, as OpenCV's minEigThreshold) are marked lost.
  double min_eigen_threshold = 1e-4;
  // Start each search at the point's entry of *points_out instead of at its
  // entry of points_in (OpenCV's OPTFLOW_USE_INITIAL_FLOW).
  bool use_initial_guess = false;
  // Points per task: chunks amortise OpenCV's per-call set-up.
  int chunk = 64;

  void Check() const;
};

// Builds the pyramid that PyramidalLk reads (with derivatives, so that an
// image tracked from more than once has its gradients computed once).
// Buffers of *pyramid of the right size are reused.
void BuildLkPyramid(const cv::Mat& grey, const PyrLkOptions& options,
                    std::vector<cv::Mat>* pyramid);

// Tracks points_in from the `from` pyramid into the `to` pyramid; fills
// points_out, status (1 tracked) and error (OpenCV's mean absolute
// difference) with one entry per input point.
void PyramidalLk(const std::vector<cv::Mat>& from,
                 const std::vector<cv::Mat>& to,
                 const std::vector<cv::Point2f>& points_in,
                 std::vector<cv::Point2f>* points_out,
                 std::vector<uchar>* status, std::vector<float>* error,
                 const PyrLkOptions& options);

}  // namespace monomap
