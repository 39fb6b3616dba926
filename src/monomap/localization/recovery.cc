#include "monomap/localization/recovery.h"

#include <algorithm>
#include <cmath>

#include "monomap/util/error.h"

namespace monomap {

void RecoveryOptions::Check() const {
  CheckOption(injection_fraction >= 0 && injection_fraction < 1,
              "injection_fraction", "must be in [0, 1)");
  CheckOption(mcc_min_injected >= 0, "mcc_min_injected", "must be >= 0");
  CheckOption(relocalize_ncc_drop >= 0, "relocalize_ncc_drop", "must be >= 0");
  CheckOption(relocalize_min_coverage >= 0 && relocalize_min_coverage < 1,
              "relocalize_min_coverage", "must be in [0, 1)");
  CheckOption(relocalize_min_updates >= 1, "relocalize_min_updates",
              "must be >= 1");
  CheckOption(relocalize_fraction >= 0 && relocalize_fraction < 1,
              "relocalize_fraction", "must be in [0, 1)");
  CheckOption(relocalize_alpha_fast > 0 && relocalize_alpha_fast <= 1,
              "relocalize_alpha_fast", "must be in (0, 1]");
  CheckOption(relocalize_alpha_slow > 0 &&
                  relocalize_alpha_slow < relocalize_alpha_fast,
              "relocalize_alpha_slow", "must be in (0, relocalize_alpha_fast)");
}

RecoveryEstimator::RecoveryEstimator(const RecoveryOptions& options,
                                     bool with_mcc, int budget)
    : options_(options), with_mcc_(with_mcc), budget_(budget) {
  options_.Check();
  CheckOption(budget >= 1, "recovery budget", "must be >= 1");
}

bool RecoveryEstimator::Update(double best_ncc, double best_coverage) {
  if (!(options_.relocalize_ncc_drop > 0)) return relocalizing_ = false;
  // Too little map in view to judge: everything stays as it was.
  if (!(best_coverage >= options_.relocalize_min_coverage)) {
    return relocalizing_;
  }
  if (!has_average_) {
    fast_ = slow_ = best_ncc;
    has_average_ = true;
  } else {
    fast_ += options_.relocalize_alpha_fast * (best_ncc - fast_);
    slow_ += options_.relocalize_alpha_slow * (best_ncc - slow_);
  }
  // The persistence counts the updates themselves, not the fast average,
  // which keeps one bad frame for several updates.
  const double threshold = slow_ - options_.relocalize_ncc_drop;
  dropped_run_ = best_ncc < threshold ? dropped_run_ + 1 : 0;
  relocalizing_ =
      fast_ < threshold && dropped_run_ >= options_.relocalize_min_updates;
  return relocalizing_;
}

InjectionPlan RecoveryEstimator::Plan(int resampled) const {
  int n_inject =
      static_cast<int>(std::lround(options_.injection_fraction * resampled));
  if (with_mcc_) {
    // Never more than half the set: the resampled particles carry the
    // filter's belief.
    n_inject =
        std::max(n_inject, std::min(options_.mcc_min_injected, resampled / 2));
  }
  const int n_relocalize =
      relocalizing_ ? static_cast<int>(
                          std::lround(options_.relocalize_fraction * budget_))
                    : 0;
  InjectionPlan plan;
  plan.appended = std::min(n_relocalize, std::max(0, budget_ - resampled));
  plan.replaced =
      n_inject + std::min(n_relocalize - plan.appended, resampled / 2);
  return plan;
}

}  // namespace monomap
