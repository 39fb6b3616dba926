// Accuracy of one localization run (e.g. a global initialisation) against
// ground truth: per-step errors, whether and when the filter converged,
// and how well it tracked afterwards.
#pragma once

#include <vector>

#include <nlohmann/json.hpp>

#include "monomap/map/map.h"

namespace monomap {

struct LocalizationAccuracyOptions {
  // A step is "within" when its position error is below this (m) ...
  double max_translation_error_m = 0.10;
  // ... and its rotation error below this (degrees).
  double max_rotation_error_deg = 5.0;
  // Estimated and ground-truth poses are associated by timestamps closer
  // than this (s); see AssociateByTimestamp.
  double max_dt = 1e-3;

  void Check() const;
};

struct LocalizationAccuracy {
  // Estimated poses with a ground-truth pose (the evaluated steps).
  int matched = 0;
  // Per evaluated step: its index in the estimate, and its errors (camera
  // position in m, rotation angle in degrees).
  std::vector<int> step;
  std::vector<double> translation_error_m;
  std::vector<double> rotation_error_deg;
  // The last evaluated step is within the thresholds.
  bool success = false;
  // First estimate index from which every evaluated step is within the
  // thresholds to the end of the run; -1 if the last one is not (so
  // converged_step >= 0 exactly when success).
  int converged_step = -1;
  // First estimate index within the thresholds at all (-1 if none): before
  // converged_step when the filter found the pose and lost it again.
  int first_within_step = -1;
  // Share of evaluated steps within the thresholds.
  double fraction_within = 0.0;
  // Errors of the last evaluated step.
  double final_translation_error_m = 0.0;
  double final_rotation_error_deg = 0.0;
  // Mean errors from converged_step to the end (NaN if it never converged).
  double mean_translation_error_m = 0.0;
  double mean_rotation_error_deg = 0.0;
  // The same after removing one rigid offset of the estimate's frame (the
  // steps from converged_step aligned by se3-poses): a monocular map's
  // frame is its odometry's, and bundle adjustment may turn it slightly.
  // NaN if it never converged or < 3 steps did.
  double mean_translation_error_rigid_m = 0.0;
  double mean_rotation_error_rigid_deg = 0.0;
  // Mean errors over all evaluated steps.
  double mean_translation_error_all_m = 0.0;
  double mean_rotation_error_all_deg = 0.0;

  // All figures; the per-step errors only if `per_step`. NaN becomes null.
  nlohmann::json ToJson(bool per_step = true) const;
};

// Evaluates the estimate (one pose per filter step, sorted by timestamp)
// against ground truth, in the same frame (no alignment). Throws
// OptionsError on bad options and StageError if timestamps are not
// increasing or no pose matches.
LocalizationAccuracy EvaluateLocalization(
    const std::vector<TimedPose>& estimate,
    const std::vector<TimedPose>& groundtruth,
    const LocalizationAccuracyOptions& options = {});

}  // namespace monomap
