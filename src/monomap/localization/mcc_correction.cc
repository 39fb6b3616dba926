#include "monomap/localization/mcc_correction.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

#include "monomap/util/angles.h"
#include "monomap/util/error.h"

namespace monomap {

namespace {

// options.refinement at the live camera's aspect, never larger than the
// camera: upsampling the live image would only blur the tracks.
MccOptions RefinementOptions(const MccCorrectionOptions& options,
                             const Camera& camera) {
  MccOptions o = options.refinement;
  if (camera.width > 0 && camera.height > 0) {
    const double scale =
        std::min(1.0, static_cast<double>(o.width) / camera.width);
    o.width = std::max(16, static_cast<int>(std::lround(camera.width * scale)));
    o.height =
        std::max(16, static_cast<int>(std::lround(camera.height * scale)));
  }
  return o;
}

}  // namespace

void MccCorrectionOptions::Check() const {
  corrector.Check();
  refinement.Check();
  CheckOption(top_k >= 0, "mcc_top_k", "must be >= 0");
  CheckOption(spread_m >= 0, "mcc_spread_m", "must be >= 0");
  CheckOption(spread_deg >= 0, "mcc_spread_deg", "must be >= 0");
  CheckOption(merge_translation_m >= 0, "merge_translation_m", "must be >= 0");
  CheckOption(merge_rotation_deg >= 0, "merge_rotation_deg", "must be >= 0");
}

void SetEstimateRefinementWidth(int width, const char* name,
                                MccCorrectionOptions* options) {
  if (width != 0 && width < 16) {
    throw OptionsError(std::string(name) + ": must be 0 or at least 16");
  }
  options->refine_estimate = width > 0;
  // The height follows the camera's aspect (RefinementOptions).
  if (width > 0) options->refinement.width = width;
}

int EstimateRefinementWidth(const MccCorrectionOptions& options) {
  return options.refine_estimate ? options.refinement.width : 0;
}

MccCorrection::MccCorrection(const Renderer* renderer, const Camera& camera,
                             const MccCorrectionOptions& options)
    : options_((options.Check(), options)),
      corrector_(renderer, camera, options.corrector),
      refiner_(renderer, camera, RefinementOptions(options, camera)) {}

void MccCorrection::AddSizes(LiveFrameSizes* sizes) const {
  if (options_.top_k > 0) {
    sizes->correction =
        ImageSize{options_.corrector.width, options_.corrector.height};
  }
  if (options_.refine_estimate) {
    sizes->refinement =
        ImageSize{refiner_.options().width, refiner_.options().height};
  }
}

MccCorrectionStats MccCorrection::CorrectParticles(
    const LiveFrame& live, const MeasurementModel& measurement,
    const StateModel& state, std::vector<Particle>* particles,
    std::vector<MeasurementScore>* scores) const {
  MccCorrectionStats stats;
  if (options_.top_k <= 0) return stats;
  const std::vector<size_t> order =
      SpreadHeaviest(*particles, static_cast<size_t>(options_.top_k),
                     options_.spread_m, DegToRad(options_.spread_deg));
  const size_t k = order.size();
  std::vector<int> accepted(k, 0);
  tbb::parallel_for(size_t{0}, k, [&](size_t j) {
    Particle& p = (*particles)[order[j]];
    MeasurementScore& score = (*scores)[order[j]];
    const MccResult r = corrector_.Correct(live.correction(), p.world_from_cam);
    if (!r.accepted) return;
    Particle q = state.FromPose(r.world_from_cam);
    const MeasurementScore s =
        measurement.Score(live.measurement(), q.world_from_cam);
    // Keep the correction only if the image agrees at least as well.
    if (s.log_likelihood < score.log_likelihood) return;
    q.log_weight = p.log_weight;
    q.log_weight += s.log_likelihood - score.log_likelihood;
    score = s;
    p = q;
    accepted[j] = 1;
  });
  stats.attempted = static_cast<int>(k);
  stats.accepted = std::accumulate(accepted.begin(), accepted.end(), 0);
  return stats;
}

bool MccCorrection::RefineEstimate(const LiveFrame& live,
                                   const StateModel& state,
                                   Particle* estimate) const {
  if (!options_.refine_estimate) return false;
  const MccResult r =
      refiner_.Correct(live.refinement(), estimate->world_from_cam);
  if (!r.accepted) return false;
  const double log_weight = estimate->log_weight;
  *estimate = state.FromPose(r.world_from_cam);
  estimate->log_weight = log_weight;
  return true;
}

int MccCorrection::MergeDuplicates(std::vector<Particle>* particles) const {
  return MergeDuplicateParticles(particles, options_.merge_translation_m,
                                 DegToRad(options_.merge_rotation_deg));
}

}  // namespace monomap
