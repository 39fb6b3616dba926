#include "monomap/triangulation/intrinsics_refinement.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
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
  CheckOption(k3_sigma > 0, "intrinsics.k3_sigma", "must be positive");
  CheckOption(max_posterior_to_prior_std > 0 && max_posterior_to_prior_std <= 1,
              "intrinsics.max_posterior_to_prior_std", "must be in (0, 1]");
  CheckOption(
      !enabled || refine_focal || refine_principal_point || refine_radial,
      "intrinsics.refine_focal",
      "enabled needs at least one group "
      "(focal, principal point, radial) to refine");
  CheckOption(max_change_prior_sigmas > 0, "intrinsics.max_change_prior_sigmas",
              "must be positive");
  CheckOption(max_halves_sigmas > 0, "intrinsics.max_halves_sigmas",
              "must be positive");
}

std::array<double, kLensSize> LensParameters(const Camera& camera) {
  return {camera.fx,
          camera.fy,
          camera.cx,
          camera.cy,
          camera.distortion[0],
          camera.distortion[1],
          camera.distortion[ThirdRadialIndex(camera.model)]};
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
  c.distortion[ThirdRadialIndex(camera.model)] = lens[kLensK3];
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
          options.k2_sigma,
          options.k3_sigma};
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
    case kGroupK3:
      return {kLensK3};
  }
  return {};
}

const char* GroupName(int group) {
  static const char* const kNames[] = {"focal length", "principal point",
                                       "radial distortion", "k3"};
  return kNames[group];
}

}  // namespace

namespace {

// The halves' evidence on a group: the largest ratio of a half's marginal
// std to the prior's (infinite without a std) in *half_ratio, and the
// largest difference of their values in combined sigmas (returned), with
// its parameter in *worst.
double HalvesSigmas(const IntrinsicsRefinementReport& r,
                    const std::vector<int>& parameters, double* half_ratio,
                    int* worst) {
  double largest = 0.0;
  *half_ratio = 0.0;
  *worst = parameters.front();
  for (int k : parameters) {
    const double sa = r.halves_std[0][k], sb = r.halves_std[1][k];
    if (!(sa > 0.0 && sb > 0.0)) {
      *half_ratio = std::numeric_limits<double>::infinity();
      return -1.0;
    }
    *half_ratio = std::max(*half_ratio, std::max(sa, sb) / r.prior_std[k]);
    const double sigmas =
        std::abs(r.halves_candidate[0][k] - r.halves_candidate[1][k]) /
        std::hypot(sa, sb);
    if (sigmas > largest) {
      largest = sigmas;
      *worst = k;
    }
  }
  return largest;
}

// Whether group g is trusted, and one sentence saying why.
bool JudgeLensGroup(const IntrinsicsRefinementOptions& options,
                    bool posterior_ok, int g,
                    IntrinsicsRefinementReport* report, std::string* why) {
  const std::vector<int> parameters =
      GroupParameters(static_cast<LensGroup>(g), options.shared_focal);
  const std::array<double, kLensSize> given = LensParameters(report->before);
  // Worst parameter of the group: largest posterior/prior ratio, largest
  // change in prior sigmas.
  double ratio = 0.0, change = 0.0;
  for (int k : parameters) {
    const double prior = report->prior_std[k];
    ratio = std::max(ratio, report->posterior_std[k] / prior);
    change =
        std::max(change, std::abs(report->candidate[k] - given[k]) / prior);
  }
  int worst = parameters.front();
  double half_ratio = 0.0;
  const double halves =
      report->halves_checked
          ? HalvesSigmas(*report, parameters, &half_ratio, &worst)
          : -1.0;
  report->halves_sigmas[g] = halves;
  char sentence[240];
  bool trusted = false;
  const bool wanted[] = {options.refine_focal, options.refine_principal_point,
                         options.refine_radial, options.refine_k3};
  if (!wanted[g]) {
    std::snprintf(sentence, sizeof(sentence), "%s kept: not refined by option.",
                  GroupName(g));
  } else if (!posterior_ok) {
    std::snprintf(sentence, sizeof(sentence),
                  "%s kept: its covariance could not be computed (the problem "
                  "is rank deficient).",
                  GroupName(g));
  } else if (std::max(ratio, half_ratio) > options.max_posterior_to_prior_std) {
    // The whole sequence first, then each half alone.
    const bool whole = ratio > options.max_posterior_to_prior_std;
    std::snprintf(
        sentence, sizeof(sentence),
        "%s kept: %s (std %.2f of the prior's, limit %.2f).", GroupName(g),
        whole ? "not constrained by the data"
              : "a half of the frames alone does not constrain it",
        whole ? ratio : half_ratio, options.max_posterior_to_prior_std);
  } else if (change > options.max_change_prior_sigmas) {
    std::snprintf(sentence, sizeof(sentence),
                  "%s kept: it moved %.1f prior sigmas (limit %.1f), "
                  "implausible.",
                  GroupName(g), change, options.max_change_prior_sigmas);
  } else if (halves > options.max_halves_sigmas) {
    std::snprintf(sentence, sizeof(sentence),
                  "%s kept: the two halves of the frames disagree (%.5g vs "
                  "%.5g, %.1f sigmas, limit %.1f).",
                  GroupName(g), report->halves_candidate[0][worst],
                  report->halves_candidate[1][worst], halves,
                  options.max_halves_sigmas);
  } else {
    trusted = true;
    std::snprintf(sentence, sizeof(sentence),
                  "%s refined: std %.2f of the prior's, moved %.1f prior "
                  "sigmas%s.",
                  GroupName(g), ratio, change,
                  report->halves_checked ? ", the halves agree" : "");
  }
  *why = sentence;
  return trusted;
}

}  // namespace

void JudgeLensGroups(const IntrinsicsRefinementOptions& options,
                     bool posterior_ok, IntrinsicsRefinementReport* report) {
  report->reason.clear();
  for (int g = 0; g < kNumLensGroups; ++g) {
    std::string why;
    report->group_refined[g] =
        JudgeLensGroup(options, posterior_ok, g, report, &why);
    if (g == kGroupK3 && report->group_refined[g] &&
        !report->group_refined[kGroupRadial]) {
      report->group_refined[g] = false;
      why = "k3 kept: k1, k2 are, and k3 alone would absorb their error.";
    }
    report->reason += (g == 0 ? "" : " ") + why;
  }
}

}  // namespace monomap
