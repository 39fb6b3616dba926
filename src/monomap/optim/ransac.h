// Generic RANSAC over an estimator concept (in the spirit of PoseLib):
//
//   struct Estimator {
//     using Model = ...;
//     static constexpr int kSampleSize = ...;
//     size_t NumData() const;
//     // Fits models to the sampled data indices; may return 0..n models.
//     void Fit(const std::vector<size_t>& sample,
//              std::vector<Model>* models) const;
//     // Squared (or any monotone) residual of datum i under model.
//     double Residual(const Model& model, size_t i) const;
//   };
//
// Deterministic given the seed.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "monomap/util/error.h"

namespace monomap {

struct RansacOptions {
  // Number of hypotheses to draw (upper bound when adaptive stopping is on).
  int max_iterations = 2000;
  // Minimum number of hypotheses before adaptive stopping may end the loop.
  int min_iterations = 50;
  // A datum is an inlier if Residual() <= inlier_threshold.
  double inlier_threshold = 1.0;
  // Stop early once this confidence of having drawn an all-inlier sample
  // is reached; 1.0 disables adaptive stopping (always max_iterations).
  double confidence = 1.0;
  // Seed of the sampler.
  uint64_t seed = 0;

  void Check() const {
    CheckOption(max_iterations > 0, "ransac.max_iterations", "must be > 0");
    CheckOption(inlier_threshold > 0, "ransac.inlier_threshold",
                "must be > 0");
    CheckOption(confidence > 0 && confidence <= 1.0, "ransac.confidence",
                "must be in (0, 1]");
  }
};

template <typename Model>
struct RansacReport {
  bool success = false;
  Model model{};
  std::vector<size_t> inliers;
  int iterations = 0;
  // Sum of truncated residuals of the best model (MSAC score, lower=better).
  double score = std::numeric_limits<double>::infinity();
};

// MSAC: scores a hypothesis by sum(min(residual, threshold)), which prefers
// tighter fits among models with similar inlier counts.
template <typename Estimator>
RansacReport<typename Estimator::Model> Ransac(const Estimator& estimator,
                                               const RansacOptions& options) {
  options.Check();
  using Model = typename Estimator::Model;
  RansacReport<Model> report;
  const size_t n = estimator.NumData();
  const size_t k = Estimator::kSampleSize;
  if (n < k) return report;
  std::mt19937_64 rng(options.seed);
  std::vector<size_t> sample(k);
  std::vector<Model> models;
  int needed = options.max_iterations;
  int iter = 0;
  for (; iter < options.max_iterations && iter < needed; ++iter) {
    // Sample k distinct indices (rejection; k is tiny).
    for (size_t i = 0; i < k; ++i) {
      bool fresh;
      do {
        sample[i] = std::uniform_int_distribution<size_t>(0, n - 1)(rng);
        fresh = std::find(sample.begin(), sample.begin() + i, sample[i]) ==
                sample.begin() + i;
      } while (!fresh);
    }
    models.clear();
    estimator.Fit(sample, &models);
    for (const Model& m : models) {
      double score = 0.0;
      size_t count = 0;
      for (size_t i = 0; i < n && score < report.score; ++i) {
        const double r = estimator.Residual(m, i);
        if (r <= options.inlier_threshold) {
          score += r;
          ++count;
        } else {
          score += options.inlier_threshold;
        }
      }
      if (score < report.score) {
        report.score = score;
        report.model = m;
        report.success = true;
        if (options.confidence < 1.0) {
          const double w = static_cast<double>(count) / n;
          const double p_good = std::pow(w, static_cast<double>(k));
          if (p_good >= 1.0 - 1e-12) {
            needed = options.min_iterations;
          } else if (p_good > 0) {
            needed = std::max(
                options.min_iterations,
                static_cast<int>(std::ceil(std::log(1.0 - options.confidence) /
                                           std::log(1.0 - p_good))));
          }
        }
      }
    }
  }
  report.iterations = iter;
  if (report.success) {
    for (size_t i = 0; i < n; ++i) {
      if (estimator.Residual(report.model, i) <= options.inlier_threshold) {
        report.inliers.push_back(i);
      }
    }
  }
  return report;
}

}  // namespace monomap
