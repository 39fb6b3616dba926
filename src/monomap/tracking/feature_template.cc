#include "monomap/tracking/feature_template.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "monomap/util/error.h"
#include "monomap/util/image_sampling.h"

namespace monomap {

void AffineRefinementOptions::Check() const {
  CheckOption(window >= 5 && window % 2 == 1, "affine.window",
              "must be odd and >= 5");
  CheckOption(max_iterations >= 1, "affine.max_iterations", "must be >= 1");
  CheckOption(epsilon_px > 0, "affine.epsilon_px", "must be > 0");
  CheckOption(min_ncc >= -1 && min_ncc <= 1, "affine.min_ncc",
              "must be in [-1, 1]");
  CheckOption(max_correction_px > 0, "affine.max_correction_px", "must be > 0");
  CheckOption(min_eigenvalue >= 0, "affine.min_eigenvalue", "must be >= 0");
  CheckOption(noise_sigma >= 0, "affine.noise_sigma", "must be >= 0");
}

namespace {

// Whether the parallelogram A [-h, h]^2 + t lies where SampleGreyBilinear()
// reads inside the image.
bool WarpInside(const cv::Mat& img, const Eigen::Matrix2f& a,
                const Eigen::Vector2f& t, float h) {
  for (const float sx : {-h, h}) {
    for (const float sy : {-h, h}) {
      const Eigen::Vector2f p = a * Eigen::Vector2f(sx, sy) + t;
      if (!(p.x() >= 0.0f && p.y() >= 0.0f && p.x() < img.cols - 1.001f &&
            p.y() < img.rows - 1.001f)) {
        return false;
      }
    }
  }
  return true;
}

}  // namespace

bool FeatureTemplate::Extract(const cv::Mat& grey,
                              const Eigen::Vector2f& center,
                              const AffineRefinementOptions& options) {
  values_.clear();
  jacobian_.clear();
  variance_ = 0.0;
  const int w = options.window;
  const int r = w / 2;
  // One extra pixel around the window for the central differences.
  const float h = static_cast<float>(r + 1);
  if (!WarpInside(grey, Eigen::Matrix2f::Identity(), center, h)) return false;
  const int side = w + 2;
  std::vector<float> patch(static_cast<size_t>(side) * side);
  for (int y = 0; y < side; ++y) {
    for (int x = 0; x < side; ++x) {
      patch[y * side + x] = SampleGreyBilinear(
          grey, center.x() + (x - r - 1), center.y() + (y - r - 1));
    }
  }
  double sum = 0.0, sum2 = 0.0;
  for (int y = 1; y <= w; ++y) {
    for (int x = 1; x <= w; ++x) {
      const double v = patch[y * side + x];
      sum += v;
      sum2 += v * v;
    }
  }
  const double n = static_cast<double>(w) * w;
  const double mean = sum / n;
  const double var = sum2 / n - mean * mean;
  if (!(var > 1.0)) return false;  // flat: less than 1 grey level of spread
  const float inv_sigma = static_cast<float>(1.0 / std::sqrt(var));

  window_ = w;
  values_.resize(static_cast<size_t>(n));
  jacobian_.resize(static_cast<size_t>(6 * n));
  Eigen::Matrix<double, 6, 6> hessian = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix2d gradient = Eigen::Matrix2d::Zero();
  size_t k = 0;
  for (int y = 1; y <= w; ++y) {
    for (int x = 1; x <= w; ++x, ++k) {
      const float* p = &patch[y * side + x];
      values_[k] = (p[0] - static_cast<float>(mean)) * inv_sigma;
      const float gx = 0.5f * (p[1] - p[-1]) * inv_sigma;
      const float gy = 0.5f * (p[side] - p[-side]) * inv_sigma;
      const float ox = static_cast<float>(x - r - 1);
      const float oy = static_cast<float>(y - r - 1);
      float* j = &jacobian_[6 * k];
      j[0] = gx * ox;
      j[1] = gx * oy;
      j[2] = gy * ox;
      j[3] = gy * oy;
      j[4] = gx;
      j[5] = gy;
      const Eigen::Map<const Eigen::Matrix<float, 6, 1>> jv(j);
      hessian += (jv * jv.transpose()).cast<double>();
      gradient += Eigen::Vector2d(gx, gy) * Eigen::Vector2d(gx, gy).transpose();
    }
  }
  // The translation block must be well conditioned (a corner, not an edge).
  const double min_eig =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(gradient).eigenvalues()(0);
  const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> ldlt(hessian);
  if (min_eig / n < options.min_eigenvalue || ldlt.info() != Eigen::Success ||
      !ldlt.isPositive() || ldlt.vectorD().minCoeff() <= 0.0) {
    values_.clear();
    jacobian_.clear();
    return false;
  }
  variance_ = var;
  hessian_inverse_ = ldlt.solve(Eigen::Matrix<double, 6, 6>::Identity());
  return true;
}

namespace {

// Resamples the image under the warp (A, t) over [-r, r]^2 into samples,
// row by row (the offsets of a row advance by A's first column); sets their
// mean and variance. The warp must lie where SampleGreyBilinear() reads
// inside the image.
void SampleWarpedPatch(const cv::Mat& grey, const Eigen::Matrix2f& a,
                       const Eigen::Vector2f& t, int r,
                       std::vector<float>* samples, double* mean, double* var) {
  double sum = 0.0, sum2 = 0.0;
  size_t k = 0;
  for (int y = -r; y <= r; ++y) {
    Eigen::Vector2f p = a * Eigen::Vector2f(-r, y) + t;
    const Eigen::Vector2f step = a.col(0);
    for (int x = -r; x <= r; ++x, ++k, p += step) {
      const float v = SampleGreyBilinear(grey, p.x(), p.y());
      (*samples)[k] = v;
      sum += v;
      sum2 += static_cast<double>(v) * v;
    }
  }
  const size_t n = samples->size();
  *mean = sum / n;
  *var = sum2 / n - *mean * *mean;
}

// Gauss-Newton right-hand side b = J^T e of the normalized samples against
// the template (values, jacobian: 6 per value); returns sum e^2.
double TemplateResidual(const std::vector<float>& samples, double mean,
                        double var, const std::vector<float>& values,
                        const std::vector<float>& jacobian,
                        Eigen::Matrix<double, 6, 1>* b) {
  const float inv_sigma = static_cast<float>(1.0 / std::sqrt(var));
  const float fmean = static_cast<float>(mean);
  float b_f[6] = {0, 0, 0, 0, 0, 0};
  double sq = 0.0;
  for (size_t i = 0; i < values.size(); ++i) {
    const float e = (samples[i] - fmean) * inv_sigma - values[i];
    sq += static_cast<double>(e) * e;
    const float* j = &jacobian[6 * i];
    for (int q = 0; q < 6; ++q) b_f[q] += j[q] * e;
  }
  for (int q = 0; q < 6; ++q) (*b)(q) = b_f[q];
  return sq;
}

// Inverse compositional update of the warp (A, t): W <- W o W(dp)^-1.
// False if W(dp) is (nearly) singular.
bool ComposeInverse(const Eigen::Matrix<double, 6, 1>& dp, Eigen::Matrix2f* a,
                    Eigen::Vector2f* t) {
  Eigen::Matrix2d d;
  d << 1.0 + dp(0), dp(1), dp(2), 1.0 + dp(3);
  if (std::abs(d.determinant()) < 1e-6) return false;
  const Eigen::Matrix2d d_inv = d.inverse();
  const Eigen::Matrix2f a_new = (a->cast<double>() * d_inv).cast<float>();
  const Eigen::Vector2f t_new =
      *t - (a->cast<double>() * d_inv * dp.tail<2>()).cast<float>();
  *a = a_new;
  *t = t_new;
  return true;
}

// A warp that did not settle, folded or shrank/grew wildly, matches
// poorly, or ran far from the frame-to-frame position t0 has locked onto
// something else.
bool LockedElsewhere(const Eigen::Matrix2f& a, const Eigen::Vector2f& t,
                     const Eigen::Vector2f& t0, bool converged, double ncc,
                     double min_ncc, const AffineRefinementOptions& options) {
  const Eigen::JacobiSVD<Eigen::Matrix2f> svd(a);
  const float s_max = svd.singularValues()(0), s_min = svd.singularValues()(1);
  return !converged || a.determinant() <= 0.0f || s_min < 0.5f ||
         s_max > 2.0f || ncc < min_ncc ||
         (t - t0).norm() > options.max_correction_px;
}

}  // namespace

AffineRefinement FeatureTemplate::Refine(
    const cv::Mat& grey, Eigen::Matrix2f* a_io, Eigen::Vector2f* t_io,
    const AffineRefinementOptions& options) const {
  AffineRefinement result;
  if (values_.empty()) return result;
  const int r = window_ / 2;
  const size_t n = values_.size();
  Eigen::Matrix2f a = *a_io;
  Eigen::Vector2f t = *t_io;
  std::vector<float> samples(n);
  double last_ncc = -1.0;
  float last_step = std::numeric_limits<float>::infinity();
  for (int it = 0; it < options.max_iterations; ++it) {
    if (!WarpInside(grey, a, t, static_cast<float>(r))) return result;
    double mean, var;
    SampleWarpedPatch(grey, a, t, r, &samples, &mean, &var);
    if (!(var > 1e-6)) return result;
    Eigen::Matrix<double, 6, 1> b;
    const double sq =
        TemplateResidual(samples, mean, var, values_, jacobian_, &b);
    // Both patches have unit variance: mean squared difference = 2 - 2 NCC.
    last_ncc = 1.0 - 0.5 * sq / n;
    result.iterations = it + 1;
    const Eigen::Matrix<double, 6, 1> dp = hessian_inverse_ * b;
    const Eigen::Vector2f t_before = t;
    if (!ComposeInverse(dp, &a, &t)) return result;
    // Converged when the feature point (the patch centre) settles; the
    // patch corners may still wobble by a few hundredths of a pixel.
    const float moved = (t - t_before).norm();
    if (!a.allFinite() || !t.allFinite()) return result;
    last_step = moved;
    if (moved < options.epsilon_px) break;
  }
  // Noise keeps some alignments hovering: a last step within a few
  // epsilons of the feature point is as good as settled.
  const bool converged = last_step < 5.0f * options.epsilon_px;
  result.ncc = last_ncc;
  // Both patches carry noise of variance sigma^2 against the reference's
  // variance_ (which includes it): 2 - 2 NCC grows by 2 sigma^2 / variance_.
  const double noise_cost =
      options.noise_sigma * options.noise_sigma / variance_;
  if (LockedElsewhere(a, t, *t_io, converged, last_ncc,
                      options.min_ncc - noise_cost, options)) {
    return result;
  }
  result.accepted = true;
  *a_io = a;
  *t_io = t;
  return result;
}

double EstimateImageNoiseSigma(const cv::Mat& grey) {
  if (grey.type() != CV_8UC1 || grey.rows < 3 || grey.cols < 3) {
    throw InputError(
        "noise estimation needs an 8-bit grey image of 3x3 or more");
  }
  // Second differences in both directions: zero on planes and ramps; on
  // white noise of variance s^2 the response has variance 36 s^2.
  const cv::Mat kernel =
      (cv::Mat_<float>(3, 3) << 1, -2, 1, -2, 4, -2, 1, -2, 1);
  cv::Mat response;
  cv::filter2D(grey, response, CV_32F, kernel);
  const cv::Mat inner =
      cv::abs(response(cv::Rect(1, 1, grey.cols - 2, grey.rows - 2)));
  std::vector<float> values(inner.begin<float>(), inner.end<float>());
  auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  // The median of |N(0, 1)| is 0.6745.
  return *mid / (0.6745 * 6.0);
}

}  // namespace monomap
