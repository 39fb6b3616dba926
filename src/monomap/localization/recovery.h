// Recovery of a lost filter: random particles put into each resampled set.
// A small share always (injection), and, while the image disagrees with
// the map where the best particle sees it (relocalization), a share of the
// particle budget. The disagreement is a drop of the best particle's NCC,
// found from a fast and a slow average as in the augmented MCL of Thrun et
// al., Probabilistic Robotics, 8.3.5. The trigger reads the NCC over the
// map pixels only, not the likelihood (which also falls with the share of
// the view the map covers), and skips views that show too little map to
// judge: a camera looking past the map's edge is not a wrong pose.
#pragma once

namespace monomap {

struct RecoveryOptions {
  // Fraction of each resampled set replaced by particles drawn over the
  // whole area, so the filter recovers when kidnapped.
  double injection_fraction = 0.02;
  // MCC: at least this many injected per resampling. MCC merges the set
  // down to a handful of hypotheses, so the fraction injects ~2; each
  // injected particle is corrected, and one landing in MCC's ~20 cm basin
  // of the true pose recovers the filter. 4 balances that against wrong
  // modes found this way (docs/benchmarks.md, "Kidnapped robot").
  int mcc_min_injected = 4;
  // Relocalization threshold: the fast average of the best particle's NCC
  // falling more than this below the slow one. The best particle, not the
  // mean, so that injected particles do not lower the signal. 0: off. The
  // default lies between tracking's fluctuations and a kidnapping's drop
  // (docs/benchmarks.md, "Kidnapped robot with relocalization").
  double relocalize_ncc_drop = 0.035;
  // Updates whose best particle sees less map than this share of its view
  // are not judged (the averages and the state stay as they were): NCC
  // over a sliver of map, much of it the map's blurred edge, says little.
  double relocalize_min_coverage = 0.3;
  // Each of this many judged updates in a row must also lie that far below
  // the slow average before the filter relocalizes: one bad frame (motion
  // blur, a hand) is not a kidnapping.
  int relocalize_min_updates = 2;
  // Share of the particle budget injected per resampling while
  // relocalizing.
  double relocalize_fraction = 0.1;
  // Smoothing of the fast and slow averages (weight of the newest update).
  double relocalize_alpha_fast = 0.5;
  double relocalize_alpha_slow = 0.01;

  void Check() const;
};

// How many random particles go into a resampled set.
struct InjectionPlan {
  int replaced = 0;  // random particles in place of resampled ones
  int appended = 0;  // random particles added (up to the budget)
};

class RecoveryEstimator {
 public:
  // `with_mcc`: the set is corrected by MCC (mcc_min_injected applies).
  // `budget`: the particle budget. Throws OptionsError on bad options.
  RecoveryEstimator(const RecoveryOptions& options, bool with_mcc, int budget);

  // Forgets the averages (after an initialization).
  void Reset() {
    has_average_ = false;
    relocalizing_ = false;
    dropped_run_ = 0;
  }
  // Feeds one update's best particle (highest likelihood): its NCC and the
  // share of its view the map covers. Returns whether the filter is
  // relocalizing (always false with relocalize_ncc_drop 0).
  bool Update(double best_ncc, double best_coverage);
  bool relocalizing() const { return relocalizing_; }
  // The random particles for a resampled set of `resampled` particles:
  // injection always, relocalization while relocalizing. Relocalization
  // adds up to the budget and replaces (at most half the set) beyond it.
  InjectionPlan Plan(int resampled) const;

 private:
  RecoveryOptions options_;
  bool with_mcc_;
  int budget_;
  bool has_average_ = false;
  double fast_ = 0.0, slow_ = 0.0;
  int dropped_run_ = 0;  // judged updates in a row below the threshold
  bool relocalizing_ = false;
};

}  // namespace monomap
