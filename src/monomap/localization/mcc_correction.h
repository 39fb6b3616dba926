// The correction stage of MCC-based localization: after weighing, the
// heaviest particles (spread over the pose space) are moved by Monte Carlo
// Correction (mcc.h) onto the pose the live image supports, the update's
// estimate is corrected once more against a larger render, and after
// resampling the duplicates the corrections create are merged.
#pragma once

#include <vector>

#include "monomap/camera/camera.h"
#include "monomap/localization/live_frame.h"
#include "monomap/localization/mcc.h"
#include "monomap/localization/measurement_model.h"
#include "monomap/localization/particle_filter.h"
#include "monomap/localization/state_model.h"
#include "monomap/rendering/renderer.h"

namespace monomap {

struct MccCorrectionOptions {
  // The correction of the particles (its width x height: their renders).
  MccOptions corrector;
  // How many of the heaviest particles are corrected per update. Many
  // while the particles are spread (a global start needs them to find the
  // true pose's basin); once they have merged into a few, all are.
  int top_k = 64;
  // Those particles are picked heaviest first but at least this far apart
  // (m, or deg of heading/rotation), so that a crowd in one wrong mode does
  // not take every correction while a lighter particle in the true pose's
  // basin gets none. When too few are that far apart, the heaviest of the
  // rest fill up. 0: plain top k.
  double spread_m = 0.1;
  double spread_deg = 10.0;
  // Correct the estimate of each update once more against a render of
  // `refinement`'s (larger) size; only the output changes, not the
  // particles. Off: it pays only with a lens accurate to the image's rim
  // (a refitted one); with a map's shipped lens, and in the simulated
  // worlds, it was no better or worse, at 3-5 times the update's cost
  // (docs/design-notes.md, "Localization").
  bool refine_estimate = false;
  // Options of that refinement: its width is the largest used (the live
  // camera's size is kept if smaller), its height follows the camera's
  // aspect.
  MccOptions refinement = [] {
    MccOptions o;
    o.width = 1024;
    o.height = 768;
    o.klt_window = 21;
    // The estimate is near the truth already; a deeper pyramid lets
    // tracks at the map's silhouette run off (see MccOptions::klt_levels).
    o.klt_levels = 2;
    // converged_px stays 0: stopping early saves time but costs 6-DoF
    // accuracy (docs/design-notes.md, "Localization"); opt-in.
    return o;
  }();
  // Particles closer than this after resampling are merged (m, deg).
  double merge_translation_m = 0.005;
  double merge_rotation_deg = 0.5;

  void Check() const;
};

// The refinement as the CLI and the ROS node take it, one number: 0 turns
// it off, a width (>= 16) turns it on at that width. Throws OptionsError
// naming `name` for anything else.
void SetEstimateRefinementWidth(int width, const char* name,
                                MccCorrectionOptions* options);
// That number for `options` (0: off).
int EstimateRefinementWidth(const MccCorrectionOptions& options);

// What the particle corrections of one update did.
struct MccCorrectionStats {
  int attempted = 0;
  int accepted = 0;
};

class MccCorrection {
 public:
  // `renderer` must outlive the stage; `camera` is the live camera.
  MccCorrection(const Renderer* renderer, const Camera& camera,
                const MccCorrectionOptions& options);

  // The live image sizes the stage reads (LiveFrame::correction() and
  // refinement(); the refinement's only with refine_estimate).
  void AddSizes(LiveFrameSizes* sizes) const;

  // Corrects the heaviest particles in place (in parallel). A correction is
  // kept only if the measurement agrees at least as well; the particle's
  // log weight and `scores` then take the new score.
  MccCorrectionStats CorrectParticles(
      const LiveFrame& live, const MeasurementModel& measurement,
      const StateModel& state, std::vector<Particle>* particles,
      std::vector<MeasurementScore>* scores) const;
  // Corrects the estimate against the refinement render; false (estimate
  // unchanged) without refine_estimate or if the correction is refused.
  bool RefineEstimate(const LiveFrame& live, const StateModel& state,
                      Particle* estimate) const;
  // Merges duplicates after resampling; returns how many were removed.
  int MergeDuplicates(std::vector<Particle>* particles) const;

 private:
  MccCorrectionOptions options_;
  MonteCarloCorrector corrector_;
  MonteCarloCorrector refiner_;
};

}  // namespace monomap
