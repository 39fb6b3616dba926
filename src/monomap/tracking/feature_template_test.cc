#include "monomap/tracking/feature_template.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "monomap/util/angles.h"
#include "monomap/util/error.h"

namespace monomap {
namespace {

// Smoothed noise: texture everywhere, so every patch is alignable.
cv::Mat MakeNoiseImage(int size, uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat noise(size, size, CV_32F);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, 1.0);
  cv::GaussianBlur(noise, noise, cv::Size(0, 0), 2.0);
  cv::Scalar mean, stddev;
  cv::meanStdDev(noise, mean, stddev);
  cv::Mat out;
  noise.convertTo(out, CV_8U, 40.0 / stddev[0],
                  128.0 - 40.0 * mean[0] / stddev[0]);
  return out;
}

// The image warped by x' = a (x - c) + c + t, then with gain and bias.
cv::Mat Warp(const cv::Mat& image, const Eigen::Matrix2d& a,
             const Eigen::Vector2d& c, const Eigen::Vector2d& t, double gain,
             double bias) {
  const Eigen::Vector2d offset = c + t - a * c;
  const cv::Matx23d m(a(0, 0), a(0, 1), offset.x(), a(1, 0), a(1, 1),
                      offset.y());
  cv::Mat warped;
  cv::warpAffine(image, warped, m, image.size(), cv::INTER_CUBIC);
  cv::Mat out;
  warped.convertTo(out, CV_8U, gain, bias);
  return out;
}

TEST(FeatureTemplateTest, RecoversAffineWarpUnderExposureChange) {
  const cv::Mat reference = MakeNoiseImage(200, 3);
  const Eigen::Vector2d centre(100.3, 99.6);
  AffineRefinementOptions options;
  FeatureTemplate feature;
  ASSERT_TRUE(feature.Extract(reference, centre.cast<float>(), options));

  // 12% zoom, 6 degrees of rotation, some shear, a shift; darker image.
  const double angle = DegToRad(6.0);
  Eigen::Matrix2d rotation;
  rotation << std::cos(angle), -std::sin(angle), std::sin(angle),
      std::cos(angle);
  Eigen::Matrix2d shear;
  shear << 1.0, 0.04, 0.0, 1.0;
  const Eigen::Matrix2d true_a = 1.12 * rotation * shear;
  const Eigen::Vector2d true_t(3.4, -2.2);
  const cv::Mat current = Warp(reference, true_a, centre, true_t, 0.7, 20.0);

  // Start as frame-to-frame tracking would leave it: identity shape, the
  // position 0.8 px off.
  Eigen::Matrix2f a = Eigen::Matrix2f::Identity();
  Eigen::Vector2f t =
      (centre + true_t + Eigen::Vector2d(0.5, -0.6)).cast<float>();
  const AffineRefinement r = feature.Refine(current, &a, &t, options);
  ASSERT_TRUE(r.accepted);
  EXPECT_GT(r.ncc, 0.97);
  EXPECT_LT((t.cast<double>() - (centre + true_t)).norm(), 0.03);
  EXPECT_LT((a.cast<double>() - true_a).norm(), 0.02);
}

TEST(FeatureTemplateTest, RejectsFlatPatchesAndWrongMatches) {
  AffineRefinementOptions options;
  FeatureTemplate flat;
  EXPECT_FALSE(flat.Extract(cv::Mat(100, 100, CV_8U, cv::Scalar(90)),
                            Eigen::Vector2f(50, 50), options));
  EXPECT_TRUE(flat.empty());
  // A patch near the border does not fit.
  const cv::Mat image = MakeNoiseImage(100, 4);
  FeatureTemplate border;
  EXPECT_FALSE(border.Extract(image, Eigen::Vector2f(3, 50), options));

  // Aligning against an unrelated image fails and leaves the warp as is.
  FeatureTemplate feature;
  ASSERT_TRUE(feature.Extract(image, Eigen::Vector2f(50, 50), options));
  const cv::Mat other = MakeNoiseImage(100, 5);
  Eigen::Matrix2f a = Eigen::Matrix2f::Identity();
  Eigen::Vector2f t(50, 50);
  const AffineRefinement r = feature.Refine(other, &a, &t, options);
  EXPECT_FALSE(r.accepted);
  EXPECT_EQ(t, Eigen::Vector2f(50, 50));
  EXPECT_EQ(a, Eigen::Matrix2f::Identity());
}

// `image` with Gaussian noise of `sigma` grey levels added.
cv::Mat AddNoise(const cv::Mat& image, double sigma, uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat noise(image.size(), CV_32F);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, sigma);
  cv::Mat sum;
  image.convertTo(sum, CV_32F);
  sum += noise;
  cv::Mat out;
  sum.convertTo(out, CV_8U);
  return out;
}

TEST(FeatureTemplateTest, NoiseEstimateMatchesTheAddedNoise) {
  const cv::Mat texture = MakeNoiseImage(400, 8);
  // Quantisation alone: well under one grey level.
  EXPECT_LT(EstimateImageNoiseSigma(texture), 0.6);
  for (const double sigma : {1.0, 2.0, 5.0}) {
    const double estimate =
        EstimateImageNoiseSigma(AddNoise(texture, sigma, 9));
    std::printf("noise %.1f: estimated %.3f\n", sigma, estimate);
    // The texture's own curvature adds a little (0.2 at 1 grey level).
    EXPECT_NEAR(estimate, sigma, 0.1 * sigma + 0.25);
  }
  EXPECT_THROW(EstimateImageNoiseSigma(cv::Mat()), InputError);
  EXPECT_THROW(EstimateImageNoiseSigma(cv::Mat(10, 10, CV_32F)), InputError);
}

// Texture of 4 grey levels' spread under noise of 2 (a painted wall seen by
// a webcam): noise alone holds an exact alignment's NCC near 0.8, under the
// plain 0.85 bar. Allowing for the noise lets such features align, and a
// wrong match still fails.
TEST(FeatureTemplateTest, NoiseAwareBarAlignsLowContrastTexture) {
  const cv::Mat smooth = MakeNoiseImage(300, 10);
  cv::Mat faint;
  smooth.convertTo(faint, CV_8U, 0.1, 128.0 - 12.8);  // spread 40 -> 4
  const cv::Mat reference = AddNoise(faint, 2.0, 11);
  const Eigen::Vector2d shift(0.4, -0.3);
  const cv::Mat current = AddNoise(
      Warp(faint, Eigen::Matrix2d::Identity(), {150, 150}, shift, 1.0, 0.0),
      2.0, 12);
  cv::Mat other_faint;
  MakeNoiseImage(300, 13).convertTo(other_faint, CV_8U, 0.1, 128.0 - 12.8);
  const cv::Mat unrelated = AddNoise(other_faint, 2.0, 14);
  AffineRefinementOptions plain, noise_aware;
  noise_aware.noise_sigma = 2.0;
  int tried = 0, plain_ok = 0, aware_ok = 0, wrong_ok = 0;
  std::vector<double> errors;
  for (int y = 40; y <= 260; y += 20) {
    for (int x = 40; x <= 260; x += 20) {
      FeatureTemplate feature;
      const Eigen::Vector2f at(x, y);
      if (!feature.Extract(reference, at, plain)) continue;
      ++tried;
      for (const AffineRefinementOptions* options : {&plain, &noise_aware}) {
        Eigen::Matrix2f a = Eigen::Matrix2f::Identity();
        Eigen::Vector2f t = at;
        if (!feature.Refine(current, &a, &t, *options).accepted) continue;
        if (options == &plain) {
          ++plain_ok;
        } else {
          ++aware_ok;
          errors.push_back(((t - at).cast<double>() - shift).norm());
        }
      }
      Eigen::Matrix2f a = Eigen::Matrix2f::Identity();
      Eigen::Vector2f t = at;
      wrong_ok += feature.Refine(unrelated, &a, &t, noise_aware).accepted;
    }
  }
  std::sort(errors.begin(), errors.end());
  const double median = errors.empty() ? 1e9 : errors[errors.size() / 2];
  std::printf(
      "faint texture: %d patches, aligned %d plain, %d noise-aware "
      "(median error %.3f px), %d wrong matches accepted\n",
      tried, plain_ok, aware_ok, median, wrong_ok);
  ASSERT_GE(tried, 100);
  EXPECT_LE(plain_ok, 0.3 * tried);
  EXPECT_GE(aware_ok, 0.9 * tried);
  // Noise of half the texture's spread limits the position to ~0.2 px.
  EXPECT_LT(median, 0.3);
  EXPECT_LE(wrong_ok, 0.05 * tried);  // 2 of 144 when written
}

TEST(FeatureTemplateTest, OptionsAreChecked) {
  AffineRefinementOptions options;
  options.window = 14;
  EXPECT_THROW(options.Check(), OptionsError);
  options = AffineRefinementOptions();
  options.min_ncc = 1.5;
  EXPECT_THROW(options.Check(), OptionsError);
  options = AffineRefinementOptions();
  options.noise_sigma = -1.0;
  EXPECT_THROW(options.Check(), OptionsError);
}

}  // namespace
}  // namespace monomap
