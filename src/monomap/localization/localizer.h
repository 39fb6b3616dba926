// Monte Carlo Localization of a camera against a map of textured planes by
// anticipatory rendering: each particle's view of the map is rendered
// small and compared with the live image (measurement_model.h). With
// method kMcc the best particles are also corrected by tracking the render
// into the live image (mcc.h) before resampling, and duplicates that the
// correction creates are merged after it.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "monomap/io/dataset.h"
#include "monomap/localization/mcc.h"
#include "monomap/localization/measurement_model.h"
#include "monomap/localization/particle_filter.h"
#include "monomap/map/map.h"
#include "monomap/rendering/renderer.h"

namespace monomap {

enum class LocalizationMethod { kMcl, kMcc };
enum class LocalizationState { kPlanar, k6Dof };
enum class LocalizationInit { kGlobal, kPose };

// "mcl"/"mcc", "planar"/"6dof", "global"/"pose"; throw OptionsError.
LocalizationMethod ParseLocalizationMethod(const std::string& s);
LocalizationState ParseLocalizationState(const std::string& s);
LocalizationInit ParseLocalizationInit(const std::string& s);

struct LocalizerOptions {
  // Plain MCL, or MCL with Monte Carlo Correction of the best particles.
  LocalizationMethod method = LocalizationMethod::kMcl;
  // Planar: the state is the robot base (x, y, yaw) and the camera sits on
  // it through base_from_cam; 6-DoF: the state is world_from_cam.
  LocalizationState state = LocalizationState::kPlanar;
  // Particles spread over the map area, or around a given pose.
  LocalizationInit init = LocalizationInit::kPose;
  // Initial particle count (and the fixed count when use_kld is false).
  int num_particles = 1000;
  // Adapt the count by KLD-sampling at each resampling.
  bool use_kld = true;
  KldOptions kld;
  OdometryNoise2d noise2d;
  OdometryNoise6d noise6d;
  MeasurementOptions measurement;
  MccOptions mcc;
  // MCC: how many of the heaviest particles are corrected per step. Many
  // while the particles are spread (global start: room seed 5 localized
  // with 64, lost with 8); once they have merged into a few, all are.
  int mcc_top_k = 64;
  // MCC: those particles are picked heaviest first but at least this far
  // apart (m, or deg of heading/rotation), so that a crowd of particles in
  // one wrong mode does not take every correction while a lighter
  // particle in the true pose's basin gets none. When too few are that
  // far apart, the heaviest of the rest fill up. 0: plain top k.
  double mcc_spread_m = 0.1;
  double mcc_spread_deg = 10.0;
  // MCC: the estimate of each update is corrected once more against a
  // render of refine_mcc's (larger) size; only the output changes, not the
  // particles. The particle corrections run small for speed, and at
  // 160x120 a pixel is ~0.6 degrees of view.
  bool refine_estimate = true;
  // Options of that refinement: its width is the largest used (the live
  // camera's size is kept if smaller), its height follows the camera's
  // aspect.
  MccOptions refine_mcc = [] {
    MccOptions o;
    o.width = 1024;
    o.height = 768;
    o.klt_window = 21;
    // The estimate is near the truth already; a deeper pyramid lets
    // tracks at the map's silhouette run off (see MccOptions::klt_levels).
    o.klt_levels = 2;
    return o;
  }();
  // MCC: particles closer than this after resampling are merged (m, deg).
  double merge_translation_m = 0.005;
  double merge_rotation_deg = 0.5;
  // Resample when ESS < resample_ess_fraction * particles (1: always).
  double resample_ess_fraction = 1.0;
  // Fraction of each resampled set replaced by particles drawn over the
  // whole area, so the filter recovers when kidnapped.
  double injection_fraction = 0.02;
  // MCC: at least this many injected per resampling. MCC merges the set
  // down to a handful of hypotheses (a KLD minimum of 100 mostly
  // duplicates), so the fraction injects ~2; every injected particle is
  // corrected, and one that lands in MCC's ~20 cm basin of the true pose
  // recovers the filter from a wrong mode. More also find wrong modes
  // that outscore the truth: room, 20 seeds, MCC 3000 / 750 particles
  // succeeded 20 / 15 times with ~2, 20 / 17 with 4, 18 / 19 with 8.
  int mcc_min_injected = 4;
  // Relocalization. MCC merges the set down to a handful of particles, so
  // injection sized by the set (above) stays at a few particles even when
  // the filter is lost. Here a loss is detected from the best particle's
  // log-likelihood: when its fast average falls more than
  // relocalize_ncc_drop / measurement.sigma (the same drop of NCC whatever
  // the likelihood's temperature) below its slow average,
  // relocalize_fraction of the particle budget
  // (num_particles) is injected over the area at each resampling, until
  // the drop is found (the fast average rises) or becomes the norm (the
  // slow one falls). The best particle, not the mean, so that the injected
  // particles themselves do not lower the signal. 0: off. 0.035 (0.7 log
  // units at sigma 0.05) lies between tracking's fluctuations and a
  // kidnapping's drop in the sweeps (docs/benchmarks.md, "Kidnapped robot
  // with relocalization").
  double relocalize_ncc_drop = 0.035;
  // Share of the budget injected per resampling while relocalizing.
  double relocalize_fraction = 0.1;
  // Smoothing of the fast and slow averages (weight of the newest update).
  double relocalize_alpha_fast = 0.5;
  double relocalize_alpha_slow = 0.01;
  // Pose init in LocalizeSequence: the pose (world_from_cam) the particles
  // are spread around. Empty: the first frame's odometry pose, what a robot
  // would know. Ground truth is never used.
  std::optional<Rigid3d> init_pose;
  // Pose init: standard deviations of the spread (m, degrees); with the
  // 6-DoF state they apply per axis.
  double init_spread_m = 0.05;
  double init_spread_deg = 3.0;
  // Global init and injection area (world x, y). Empty (min >= max): the
  // bounding box of the map's trajectory (or of its planes) grown by
  // area_margin_m.
  Eigen::Vector2d area_min = Eigen::Vector2d::Zero();
  Eigen::Vector2d area_max = Eigen::Vector2d::Zero();
  double area_margin_m = 0.2;
  // The estimate is the weighted mean of particles within this distance
  // and angle of the heaviest one.
  double cluster_radius_m = 0.15;
  double cluster_angle_deg = 15.0;
  RendererOptions renderer;
  uint64_t seed = 1;

  void Check() const;
};

// An odometry increment between the previous and the current frame.
struct OdometryIncrement {
  // 6-DoF: relative camera motion from odometry.txt poses.
  Rigid3d cam_prev_from_cam_cur;
  // Planar: odometry base poses of both frames (odometry2d.txt).
  Pose2d base_prev, base_cur;
};

struct LocalizerStepStats {
  int particles = 0;         // after resampling (or merging)
  int particles_weighed = 0;  // rendered this step
  double ess = 0.0;          // before resampling
  double max_weight = 0.0;   // normalized, before resampling
  double best_ncc = 0.0;
  double cluster_weight = 0.0;  // weight share of the estimate's cluster
  int kld_bins = 0;
  int injected = 0;
  bool relocalizing = false;  // relocalize_ncc_drop was exceeded this update
  int mcc_attempted = 0;
  int mcc_accepted = 0;
  int merged = 0;
  bool refined = false;      // the estimate was refined (refine_estimate)
  bool resampled = false;
  double weigh_seconds = 0.0;  // rendering + NCC of every particle
  double mcc_seconds = 0.0;    // corrections (MCC only), refinement included
  double seconds = 0.0;        // the whole step
};

struct LocalizerEstimate {
  Rigid3d world_from_cam;
  Pose2d base;  // planar state only
  LocalizerStepStats stats;
};

class Localizer {
 public:
  // `camera` is the live camera (with distortion); base_from_cam is needed
  // for the planar state. Throws OptionsError on bad options.
  Localizer(const Map& map, const Camera& camera,
            const LocalizerOptions& options,
            const std::optional<Rigid3d>& base_from_cam = std::nullopt);

  // Particles uniform over the area (yaw uniform). Planar: base on the
  // floor. 6-DoF: height, roll and pitch of a random map trajectory pose
  // (or of `reference` if given).
  void InitializeGlobal(const std::optional<Rigid3d>& reference = {});
  // Particles around world_from_cam with options' spread.
  void InitializeAtPose(const Rigid3d& world_from_cam);
  // Dispatches on options.init (`pose` required for kPose).
  void Initialize(const std::optional<Rigid3d>& pose);

  // One filter update. `odometry` is ignored on the first step after
  // initialization. live_image_raw is the raw camera image.
  LocalizerEstimate Step(const cv::Mat& live_image_raw,
                         const OdometryIncrement& odometry);

  const std::vector<Particle>& particles() const { return particles_; }
  const Renderer& renderer() const { return renderer_; }
  const MeasurementModel& measurement() const { return measurement_; }
  // The area used by global init and injection.
  Eigen::Vector2d area_min() const { return area_min_; }
  Eigen::Vector2d area_max() const { return area_max_; }

 private:
  Particle RandomParticle();
  void SetPoseFromBase(Particle* p) const;

  LocalizerOptions options_;
  Camera camera_;
  std::optional<Rigid3d> base_from_cam_;
  std::vector<Rigid3d> map_trajectory_;
  Renderer renderer_;
  MeasurementModel measurement_;
  MonteCarloCorrector corrector_;
  MonteCarloCorrector refiner_;
  Eigen::Vector2d area_min_, area_max_;
  std::vector<Particle> particles_;
  Rigid3d global_reference_;
  bool has_reference_ = false;
  bool first_step_ = true;
  // Relocalization: averages of the best log-likelihood (valid once
  // has_best_average_).
  bool has_best_average_ = false;
  double best_fast_ = 0.0, best_slow_ = 0.0;
  Rng rng_;
};

// Per-sequence summary of LocalizeSequence.
struct LocalizationReport {
  int frames = 0;
  double seconds = 0.0;
  double mean_step_seconds = 0.0;
  double mean_particles = 0.0;
  int mcc_accepted = 0;
  // Against groundtruth, when the dataset has it (else 0 and false).
  bool has_errors = false;
  double rmse_translation_m = 0.0;
  double mean_rotation_error_deg = 0.0;
  double final_translation_error_m = 0.0;
  double final_rotation_error_deg = 0.0;
  // Share of frames with translation error below 0.1 m.
  double fraction_within_10cm = 0.0;
  std::vector<LocalizerStepStats> steps;
};

// Runs the filter over the dataset's frames with its odometry increments
// (odometry2d for the planar state, odometry.txt poses for 6-DoF).
// Initialization with kPose starts at options.init_pose, or else at the
// first frame's odometry pose (never at its ground truth). `trajectory`
// receives the estimates; `particle_sets` (optional) every step's particles
// after the update. Throws InputError if the dataset lacks what the state
// needs.
LocalizationReport LocalizeSequence(
    const Map& map, const Dataset& dataset, const LocalizerOptions& options,
    std::vector<TimedPose>* trajectory,
    std::vector<std::vector<Particle>>* particle_sets = nullptr);

}  // namespace monomap
