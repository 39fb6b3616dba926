#include "monomap/optim/ransac.h"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <random>

namespace monomap {
namespace {

// Fits y = a x + b to 2D points.
struct LineEstimator {
  using Model = Eigen::Vector2d;  // (a, b)
  static constexpr int kSampleSize = 2;
  const std::vector<Eigen::Vector2d>* points;
  size_t NumData() const { return points->size(); }
  void Fit(const std::vector<size_t>& s, std::vector<Model>* models) const {
    const auto& p = (*points)[s[0]];
    const auto& q = (*points)[s[1]];
    if (std::abs(q.x() - p.x()) < 1e-12) return;
    const double a = (q.y() - p.y()) / (q.x() - p.x());
    models->push_back({a, p.y() - a * p.x()});
  }
  double Residual(const Model& m, size_t i) const {
    const auto& p = (*points)[i];
    return std::abs(m(0) * p.x() + m(1) - p.y());
  }
};

TEST(Ransac, FindsLineAmongOutliers) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> uni(-10, 10);
  std::normal_distribution<double> noise(0, 0.01);
  std::vector<Eigen::Vector2d> pts;
  for (int i = 0; i < 100; ++i) {
    const double x = uni(rng);
    pts.push_back({x, 2.0 * x - 1.0 + noise(rng)});
  }
  for (int i = 0; i < 150; ++i) pts.push_back({uni(rng), uni(rng)});
  RansacOptions options;
  options.inlier_threshold = 0.05;
  options.seed = 9;
  const auto report = Ransac(LineEstimator{&pts}, options);
  ASSERT_TRUE(report.success);
  EXPECT_NEAR(report.model(0), 2.0, 0.01);
  EXPECT_NEAR(report.model(1), -1.0, 0.05);
  EXPECT_GE(report.inliers.size(), 100u);
  EXPECT_LE(report.inliers.size(), 105u);
  EXPECT_EQ(report.iterations, 2000);
  // Same seed, same answer.
  const auto again = Ransac(LineEstimator{&pts}, options);
  EXPECT_EQ(again.inliers, report.inliers);
  // Adaptive stopping draws far fewer hypotheses at 40% inliers.
  options.confidence = 0.999;
  EXPECT_LT(Ransac(LineEstimator{&pts}, options).iterations, 200);
}

}  // namespace
}  // namespace monomap
