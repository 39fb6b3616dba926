#include "monomap/eval/localization_accuracy.h"

#include <cmath>
#include <limits>
#include <tuple>
#include <utility>
#include <vector>

#include "monomap/eval/trajectory_metrics.h"
#include "monomap/util/angles.h"
#include "monomap/util/error.h"

namespace monomap {

namespace {

// NaN (and infinities) as JSON null.
nlohmann::json Number(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json();
}

// Mean errors of the matched pairs from `first` on after one rigid offset
// (se3-poses); NaN for fewer than 3 pairs.
std::pair<double, double> RigidMeanErrors(
    const std::vector<TimedPose>& estimate,
    const std::vector<TimedPose>& groundtruth,
    const std::vector<std::pair<size_t, size_t>>& pairs, size_t first) {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  if (pairs.size() < first + 3) return {kNaN, kNaN};
  std::vector<TimedPose> est, gt;
  for (size_t k = first; k < pairs.size(); ++k) {
    est.push_back(estimate[pairs[k].first]);
    gt.push_back(groundtruth[pairs[k].second]);
    // Paired by index: one timestamp for both.
    est.back().timestamp = gt.back().timestamp = static_cast<double>(k);
  }
  const TrajectoryErrors e =
      AbsoluteTrajectoryError(est, gt, Alignment::kSE3Poses);
  return {e.translation_m.mean, e.rotation_deg.mean};
}

}  // namespace

void LocalizationAccuracyOptions::Check() const {
  CheckOption(max_translation_error_m > 0, "max_translation_error_m",
              "must be > 0");
  CheckOption(max_rotation_error_deg > 0, "max_rotation_error_deg",
              "must be > 0");
  CheckOption(max_dt >= 0, "max_dt", "must be >= 0");
}

nlohmann::json LocalizationAccuracy::ToJson(bool per_step) const {
  nlohmann::json j;
  j["matched"] = matched;
  j["success"] = success;
  j["converged_step"] = converged_step;
  j["first_within_step"] = first_within_step;
  j["fraction_within"] = fraction_within;
  j["final_translation_error_m"] = Number(final_translation_error_m);
  j["final_rotation_error_deg"] = Number(final_rotation_error_deg);
  j["mean_translation_error_m"] = Number(mean_translation_error_m);
  j["mean_rotation_error_deg"] = Number(mean_rotation_error_deg);
  j["mean_translation_error_rigid_m"] = Number(mean_translation_error_rigid_m);
  j["mean_rotation_error_rigid_deg"] = Number(mean_rotation_error_rigid_deg);
  j["mean_translation_error_all_m"] = Number(mean_translation_error_all_m);
  j["mean_rotation_error_all_deg"] = Number(mean_rotation_error_all_deg);
  if (per_step) {
    j["step"] = step;
    j["translation_error_m"] = translation_error_m;
    j["rotation_error_deg"] = rotation_error_deg;
  }
  return j;
}

LocalizationAccuracy EvaluateLocalization(
    const std::vector<TimedPose>& estimate,
    const std::vector<TimedPose>& groundtruth,
    const LocalizationAccuracyOptions& options) {
  options.Check();
  const auto pairs =
      AssociateByTimestamp(estimate, groundtruth, options.max_dt);
  if (pairs.empty()) {
    throw StageError("localization evaluation: no estimated pose matches a "
                     "ground-truth timestamp");
  }
  LocalizationAccuracy a;
  a.matched = static_cast<int>(pairs.size());
  std::vector<bool> within;
  double sum_t = 0.0, sum_r = 0.0;
  int count_within = 0;
  for (const auto& [i, g] : pairs) {
    const Rigid3d& e = estimate[i].world_from_cam;
    const Rigid3d& t = groundtruth[g].world_from_cam;
    const double et = (e.translation - t.translation).norm();
    const double er = RadToDeg(AngleBetween(e.rotation, t.rotation));
    a.step.push_back(static_cast<int>(i));
    a.translation_error_m.push_back(et);
    a.rotation_error_deg.push_back(er);
    // Written so that a NaN error is never within.
    within.push_back(et < options.max_translation_error_m &&
                     er < options.max_rotation_error_deg);
    if (within.back()) {
      ++count_within;
      if (a.first_within_step < 0) a.first_within_step = a.step.back();
    }
    sum_t += et;
    sum_r += er;
  }
  const int n = a.matched;
  a.fraction_within = static_cast<double>(count_within) / n;
  a.mean_translation_error_all_m = sum_t / n;
  a.mean_rotation_error_all_deg = sum_r / n;
  a.final_translation_error_m = a.translation_error_m.back();
  a.final_rotation_error_deg = a.rotation_error_deg.back();
  a.success = within.back();

  // The longest suffix of steps within the thresholds.
  int first = n;
  while (first > 0 && within[first - 1]) --first;
  if (first < n) {
    a.converged_step = a.step[first];
    double st = 0.0, sr = 0.0;
    for (int k = first; k < n; ++k) {
      st += a.translation_error_m[k];
      sr += a.rotation_error_deg[k];
    }
    a.mean_translation_error_m = st / (n - first);
    a.mean_rotation_error_deg = sr / (n - first);
  } else {
    a.mean_translation_error_m = std::numeric_limits<double>::quiet_NaN();
    a.mean_rotation_error_deg = std::numeric_limits<double>::quiet_NaN();
  }
  std::tie(a.mean_translation_error_rigid_m, a.mean_rotation_error_rigid_deg) =
      RigidMeanErrors(estimate, groundtruth, pairs, first);
  return a;
}

}  // namespace monomap
