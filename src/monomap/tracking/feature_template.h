// Affine-photometric refinement of a tracked feature against its reference
// appearance (Shi and Tomasi, "Good features to track", 1994).
//
// Frame-to-frame Lucas-Kanade with a translation-only window drifts when
// the view deforms the window (perspective, zoom, rotation): each step
// aligns the window's gradient energy rather than the feature point, by a
// bias proportional to the deformation, and the biases add up over the
// track (measured on the simulator: ~0.05 px per frame, 2-3 px after 50
// frames, which triangulation turns into centimetres of depth). Aligning
// the current image with the feature's reference patch by an affine warp
// removes that drift: the error no longer accumulates.
//
// The warp maps template offsets x (pixels from the template centre) to
// image positions A x + t; t is where the feature is. Intensities are
// compared after normalizing both patches to zero mean and unit variance,
// so exposure changes do not bias the alignment. The solver is the inverse
// compositional Gauss-Newton of Baker and Matthews (2004): the Jacobian and
// the Hessian come from the template once, an iteration only resamples the
// image.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

namespace monomap {

struct AffineRefinementOptions {
  // Side (px, odd) of the reference patch.
  int window = 15;
  // Largest Gauss-Newton iterations per refinement.
  int max_iterations = 10;
  // Stop when the feature point moves less than this (px) in an iteration.
  double epsilon_px = 0.01;
  // A refinement counts only if the normalized cross-correlation of the
  // aligned patch with the reference reaches this (less the share that
  // image noise alone costs, see noise_sigma).
  double min_ncc = 0.85;
  // Standard deviation (grey levels) of the images' noise. Noise alone
  // lowers a perfectly aligned patch's NCC by noise_sigma^2 / s^2 (s: the
  // reference's standard deviation), so the bar is lowered by that:
  // otherwise low-contrast texture (painted walls) never aligns and its
  // features drift frame to frame. 0: the bar is min_ncc.
  double noise_sigma = 0.0;
  // ... and if it moves the feature at most this far (px) from where
  // frame-to-frame tracking put it.
  double max_correction_px = 1.5;
  // Smallest smallest-eigenvalue of the normalized patch's gradient
  // matrix (per pixel) for a patch to serve as a reference.
  double min_eigenvalue = 1e-3;

  // Throws OptionsError naming the field if a value makes no sense.
  void Check() const;
};

// Result of FeatureTemplate::Refine.
struct AffineRefinement {
  bool accepted = false;
  int iterations = 0;
  double ncc = 0.0;  // of the final alignment
};

class FeatureTemplate {
 public:
  // Samples the reference patch centred at `center` (sub-pixel, bilinear)
  // from an 8-bit grey image. False (and empty) if the patch leaves the
  // image or is too flat to align.
  bool Extract(const cv::Mat& grey, const Eigen::Vector2f& center,
               const AffineRefinementOptions& options);

  bool empty() const { return values_.empty(); }

  // Refines the warp (*a, *t) that maps the reference into `grey` (8-bit,
  // the image the feature is tracked into), starting from the given
  // values. On acceptance *a and *t hold the refined warp; otherwise they
  // are unchanged.
  AffineRefinement Refine(const cv::Mat& grey, Eigen::Matrix2f* a,
                          Eigen::Vector2f* t,
                          const AffineRefinementOptions& options) const;

 private:
  int window_ = 0;
  double variance_ = 0.0;  // of the reference patch (grey levels^2)
  // Per pixel (row-major over the window): normalized value and the six
  // Jacobian entries d value / d (a11, a12, a21, a22, tx, ty).
  std::vector<float> values_;
  std::vector<float> jacobian_;  // 6 per pixel
  Eigen::Matrix<double, 6, 6> hessian_inverse_;
};

// Standard deviation (grey levels) of an 8-bit grey image's noise: the
// median absolute response of a Laplacian-difference kernel that cancels
// smooth intensity (Immerkaer, "Fast noise variance estimation", 1996),
// scaled for Gaussian noise. The median, not the mean, so that edges and
// texture (a minority of pixels) do not count as noise. Throws InputError
// for an image that is not 8-bit grey or smaller than 3x3.
double EstimateImageNoiseSigma(const cv::Mat& grey);

}  // namespace monomap
