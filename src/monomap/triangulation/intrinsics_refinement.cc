#include "monomap/triangulation/intrinsics_refinement.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "monomap/util/error.h"

namespace monomap {

void IntrinsicsRefinementOptions::Check() const {
  CheckOption(focal_sigma_fraction > 0, "intrinsics.focal_sigma_fraction",
              "must be positive");
  CheckOption(principal_point_sigma_fraction > 0,
              "intrinsics.principal_point_sigma_fraction", "must be positive");
  CheckOption(k1_sigma > 0, "intrinsics.k1_sigma", "must be positive");
  CheckOption(k2_sigma > 0, "intrinsics.k2_sigma", "must be positive");
  CheckOption(max_posterior_to_prior_std > 0 && max_posterior_to_prior_std <= 1,
              "intrinsics.max_posterior_to_prior_std", "must be in (0, 1]");
  CheckOption(
      !enabled || refine_focal || refine_principal_point || refine_radial,
      "intrinsics.refine_focal",
      "enabled needs at least one group "
      "(focal, principal point, radial) to refine");
  CheckOption(max_change_prior_sigmas > 0, "intrinsics.max_change_prior_sigmas",
              "must be positive");
}

std::array<double, kLensSize> LensParameters(const Camera& camera) {
  return {camera.fx,
          camera.fy,
          camera.cx,
          camera.cy,
          camera.distortion[0],
          camera.distortion[1]};
}

Camera WithLens(const Camera& camera, const std::array<double, kLensSize>& lens,
                bool shared_focal) {
  Camera c = camera;
  c.fx = lens[kLensFx];
  c.fy = shared_focal ? lens[kLensFx] * camera.fy / camera.fx : lens[kLensFy];
  c.cx = lens[kLensCx];
  c.cy = lens[kLensCy];
  c.distortion[0] = lens[kLensK1];
  c.distortion[1] = lens[kLensK2];
  return c;
}

std::array<double, kLensSize> LensPriorSigmas(
    const Camera& camera, const IntrinsicsRefinementOptions& options) {
  const double pp = options.principal_point_sigma_fraction * camera.width;
  return {options.focal_sigma_fraction * camera.fx,
          options.focal_sigma_fraction * camera.fy,
          pp,
          pp,
          options.k1_sigma,
          options.k2_sigma};
}

namespace {

// The parameters of a group (fy only without a shared focal).
std::vector<int> GroupParameters(LensGroup group, bool shared_focal) {
  switch (group) {
    case kGroupFocal:
      return shared_focal ? std::vector<int>{kLensFx}
                          : std::vector<int>{kLensFx, kLensFy};
    case kGroupPrincipalPoint:
      return {kLensCx, kLensCy};
    case kGroupRadial:
      return {kLensK1, kLensK2};
  }
  return {};
}

const char* GroupName(int group) {
  static const char* const kNames[] = {"focal length", "principal point",
                                       "radial distortion"};
  return kNames[group];
}

}  // namespace

void JudgeLensGroups(const IntrinsicsRefinementOptions& options,
                     bool posterior_ok, IntrinsicsRefinementReport* report) {
  const bool shared = options.shared_focal;
  const std::array<double, kLensSize> given = LensParameters(report->before);
  report->reason.clear();
  const std::array<bool, kNumLensGroups> wanted = {
      options.refine_focal, options.refine_principal_point,
      options.refine_radial};
  for (int g = 0; g < kNumLensGroups; ++g) {
    // Worst parameter of the group: largest posterior/prior ratio, largest
    // change in prior sigmas.
    double ratio = 0.0, change = 0.0;
    for (int k : GroupParameters(static_cast<LensGroup>(g), shared)) {
      const double prior = report->prior_std[k];
      ratio = std::max(ratio, report->posterior_std[k] / prior);
      change =
          std::max(change, std::abs(report->candidate[k] - given[k]) / prior);
    }
    char sentence[200];
    if (!wanted[g]) {
      report->group_refined[g] = false;
      std::snprintf(sentence, sizeof(sentence),
                    "%s kept: not refined by "
                    "option. ",
                    GroupName(g));
    } else if (!posterior_ok) {
      report->group_refined[g] = false;
      std::snprintf(sentence, sizeof(sentence),
                    "%s kept: its covariance could not be computed (the "
                    "problem is rank deficient). ",
                    GroupName(g));
    } else if (ratio > options.max_posterior_to_prior_std) {
      report->group_refined[g] = false;
      std::snprintf(sentence, sizeof(sentence),
                    "%s kept: not constrained by the data (std %.2f of the "
                    "prior's, limit %.2f). ",
                    GroupName(g), ratio, options.max_posterior_to_prior_std);
    } else if (change > options.max_change_prior_sigmas) {
      report->group_refined[g] = false;
      std::snprintf(sentence, sizeof(sentence),
                    "%s kept: it moved %.1f prior sigmas (limit %.1f), "
                    "implausible. ",
                    GroupName(g), change, options.max_change_prior_sigmas);
    } else {
      report->group_refined[g] = true;
      std::snprintf(sentence, sizeof(sentence),
                    "%s refined: std %.2f of the prior's, moved %.1f prior "
                    "sigmas. ",
                    GroupName(g), ratio, change);
    }
    report->reason += sentence;
  }
  if (!report->reason.empty()) report->reason.pop_back();
}

}  // namespace monomap
