// Lens self-calibration inside bundle adjustment: the focal length, the
// principal point and the radial distortion (k1, k2) become one parameter
// block of the adjustment, held by a Gaussian prior at the given calibration
// (its uncertainty as sigmas). The data move a parameter only as far as they
// outweigh the prior, and afterwards each group (focal, principal point,
// radial) is trusted only if the data shrank its marginal standard deviation
// (from the Hessian, ceres::Covariance) well below the prior's and its
// change is plausible. Rejected groups keep the given values and the
// adjustment is solved again without them: a scene that does not constrain
// the lens (forward motion, a single plane, few points) keeps the given
// calibration, and the report says why.
//
// The lens block is (fx, fy, cx, cy, k1, k2); the other three distortion
// coefficients stay as given (plumb_bob p1, p2, k3; equidistant k3, k4, 0).
// The same block serves both lens models: their first two coefficients are
// the leading radial terms (in r^2 for plumb_bob, in theta^2 for
// equidistant).
#pragma once

#include <algorithm>
#include <array>
#include <string>

#include "monomap/camera/camera.h"
#include "monomap/triangulation/projection.h"

namespace monomap {

struct IntrinsicsRefinementOptions {
  // Refine focal length, principal point and k1, k2 (k3) with the poses and
  // points (when the data constrain them). Off by default: figures in
  // docs/benchmarks.md.
  bool enabled = false;
  // Groups the trial may refine (a group left out keeps the given values).
  // The principal point is off by default: no benchmark shows it helping
  // (figures: docs/benchmarks.md).
  bool refine_focal = true;
  bool refine_principal_point = false;
  bool refine_radial = true;
  // Also the third radial term (plumb_bob k3, equidistant k3), for a lens
  // whose rim a two-term model cannot follow. Trusted only with k1, k2:
  // alone it would absorb their error. Off by default: it loosens k1, k2,
  // so small scenes keep them (figures: docs/benchmarks.md).
  bool refine_k3 = false;
  // One focal length for both axes (the given fy/fx ratio is kept).
  bool shared_focal = true;
  // Prior sigma of the focal length, as a fraction of the given fx (fy).
  double focal_sigma_fraction = 0.02;
  // Prior sigma of the principal point (px), as a fraction of the width.
  double principal_point_sigma_fraction = 0.02;
  // Prior sigmas of the radial coefficients k1 and k2.
  double k1_sigma = 0.05;
  double k2_sigma = 0.05;
  // Prior sigma of k3.
  double k3_sigma = 0.05;
  // A group is trusted only if the data shrank its marginal standard
  // deviation to at most this fraction of the prior sigma (0.5: the data
  // carry at least 3 times the prior's information) ...
  double max_posterior_to_prior_std = 0.5;
  // ... and it moved at most this many prior sigmas (farther means the
  // given calibration or the adjustment is wrong: keep the given one).
  double max_change_prior_sigmas = 4.0;
  // ... and, with check_halves, the trials on the first and on the second
  // half of the frames alone each constrain it (the std test above) and
  // agree on it: their values differ by at most max_halves_sigmas of their
  // combined marginal standard deviation. The marginal std holds only if
  // the model does (lens, odometry, tracker); halves that disagree show it
  // does not, whatever the std says.
  bool check_halves = true;
  // Largest difference of the halves' values, in combined sigmas.
  double max_halves_sigmas = 3.0;
  // Throws OptionsError naming the field if a value makes no sense.
  void Check() const;
};

// Index of the lens block's parameters.
enum LensIndex {
  kLensFx,
  kLensFy,
  kLensCx,
  kLensCy,
  kLensK1,
  kLensK2,
  kLensK3
};
constexpr int kLensSize = 7;
// Groups judged (and refined or kept) together.
enum LensGroup { kGroupFocal, kGroupPrincipalPoint, kGroupRadial, kGroupK3 };
constexpr int kNumLensGroups = 4;

// Whether any group is set.
inline bool AnyLensGroup(const std::array<bool, kNumLensGroups>& groups) {
  return std::find(groups.begin(), groups.end(), true) != groups.end();
}

// Index of the third radial term in a camera's distortion array.
inline int ThirdRadialIndex(LensModel model) {
  return model == LensModel::kEquidistant ? 2 : 4;
}

struct IntrinsicsRefinementReport {
  bool attempted = false;  // options.enabled
  // Groups refined: focal, principal point, radial (k1, k2), k3.
  std::array<bool, kNumLensGroups> group_refined{};
  bool refined() const { return AnyLensGroup(group_refined); }
  // Why each group was refined or kept, one sentence per group.
  std::string reason;
  Camera before;  // the given calibration
  Camera after;   // the one the poses and points go with
  // Prior and marginal (posterior) standard deviations of fx, fy, cx, cy,
  // k1, k2, k3 from the trial adjustment; 0 if held fixed, posterior -1 if the
  // covariance could not be computed.
  std::array<double, kLensSize> prior_std{};
  std::array<double, kLensSize> posterior_std{};
  // Values after the trial adjustment.
  std::array<double, kLensSize> candidate{};
  // The trials on the first and the second half of the frames (check_halves;
  // halves_checked false otherwise): their values and marginal standard
  // deviations (-1 if not computed), and per group the largest difference
  // of the halves in combined sigmas (-1: not compared).
  bool halves_checked = false;
  std::array<std::array<double, kLensSize>, 2> halves_candidate{};
  std::array<std::array<double, kLensSize>, 2> halves_std{};
  std::array<double, kNumLensGroups> halves_sigmas = {-1, -1, -1, -1};
  double covariance_seconds = 0.0;
};

// The lens block of a camera, and the camera with a lens block applied
// (the other distortion coefficients unchanged).
std::array<double, kLensSize> LensParameters(const Camera& camera);
Camera WithLens(const Camera& camera, const std::array<double, kLensSize>& lens,
                bool shared_focal);

// Prior sigmas of the lens block for the given camera.
std::array<double, kLensSize> LensPriorSigmas(
    const Camera& camera, const IntrinsicsRefinementOptions& options);

// Which groups to trust, from the trial adjustment's candidate values and
// marginal standard deviations (posterior_ok false: the covariance could
// not be computed, nothing is trusted) and, if report->halves_checked, the
// halves' agreement; groups the options do not refine stay kept. Fills
// report->halves_sigmas, report->group_refined and report->reason.
void JudgeLensGroups(const IntrinsicsRefinementOptions& options,
                     bool posterior_ok, IntrinsicsRefinementReport* report);

namespace internal {

// Camera-frame point -> raw pixel with the lens block (fx, fy, cx, cy, k1,
// k2, k3) as parameters and the camera's other distortion coefficients
// fixed; with a shared focal, fy = fx * fy_over_fx. Caller checks z > 0.
struct LensConstants {
  bool equidistant = false;            // lens model (else plumb_bob)
  std::array<double, 5> distortion{};  // the camera's (k1, k2, k3 replaced)
  int k3_index = 4;                    // ThirdRadialIndex of the model
  bool shared_focal = true;
  double fy_over_fx = 1.0;
};
template <typename T>
inline void ProjectWithLens(const LensConstants& c, const T* lens,
                            const T* x_in_cam, T* px) {
  T distortion[5];
  for (int k = 0; k < 5; ++k) distortion[k] = T(c.distortion[k]);
  distortion[0] = lens[kLensK1];
  distortion[1] = lens[kLensK2];
  distortion[c.k3_index] = lens[kLensK3];
  T xd, yd;
  DistortNormalized(c.equidistant, distortion, T(x_in_cam[0] / x_in_cam[2]),
                    T(x_in_cam[1] / x_in_cam[2]), &xd, &yd);
  const T fy = c.shared_focal ? lens[kLensFx] * c.fy_over_fx : lens[kLensFy];
  px[0] = lens[kLensFx] * xd + lens[kLensCx];
  px[1] = fy * yd + lens[kLensCy];
}

// Gaussian prior on the lens block: (lens - given) / sigma per parameter.
struct LensPriorCost {
  std::array<double, kLensSize> given;
  std::array<double, kLensSize> inv_sigma;
  template <typename T>
  bool operator()(const T* lens, T* residual) const {
    for (int k = 0; k < kLensSize; ++k) {
      residual[k] = (lens[k] - T(given[k])) * T(inv_sigma[k]);
    }
    return true;
  }
};

}  // namespace internal
}  // namespace monomap
