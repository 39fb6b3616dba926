#include "monomap/tracking/feature_template.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

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

TEST(FeatureTemplateTest, OptionsAreChecked) {
  AffineRefinementOptions options;
  options.window = 14;
  EXPECT_THROW(options.Check(), OptionsError);
  options = AffineRefinementOptions();
  options.min_ncc = 1.5;
  EXPECT_THROW(options.Check(), OptionsError);
}

}  // namespace
}  // namespace monomap
