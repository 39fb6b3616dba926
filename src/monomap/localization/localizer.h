// Monte Carlo Localization of a camera against a map of textured planes by
// anticipatory rendering: each particle's view of the map is rendered
// small and compared with the live image (measurement_model.h). With
// method kMcc the best particles are also corrected by tracking the render
// into the live image (mcc_correction.h) before resampling, and duplicates
// that the correction creates are merged after it. One update reads:
// predict -> weigh -> correct -> estimate -> recover -> resample.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "monomap/localization/live_frame.h"
#include "monomap/localization/mcc_correction.h"
#include "monomap/localization/measurement_model.h"
#include "monomap/localization/particle_filter.h"
#include "monomap/localization/recovery.h"
#include "monomap/localization/state_model.h"
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

// The particle filter itself: count, motion and measurement models,
// resampling and the estimate.
struct MclOptions {
  // Initial particle count (and the fixed count when use_kld is false);
  // also the budget relocalization fills up to.
  int num_particles = 1000;
  // Adapt the count by KLD-sampling at each resampling.
  bool use_kld = true;
  KldOptions kld;
  // Motion noise of the planar and of the 6-DoF state.
  OdometryNoise2d noise2d;
  OdometryNoise6d noise6d;
  MeasurementOptions measurement;
  // Resample when ESS < resample_ess_fraction * particles (1: always).
  double resample_ess_fraction = 1.0;
  // The estimate is the weighted mean of particles within this distance
  // and angle of the heaviest one.
  double cluster_radius_m = 0.15;
  double cluster_angle_deg = 15.0;

  // A particle budget, as `localize --particles` means it: the initial
  // count and KLD-sampling's maximum (its minimum no higher).
  void SetParticleBudget(int particles);
  void Check() const;
};

// Where the particles start, and the area random particles are drawn in.
struct InitializationOptions {
  // Particles spread over the area, or around a pose.
  LocalizationInit kind = LocalizationInit::kPose;
  // Pose init: the pose (world_from_cam) the particles are spread around.
  // Empty: the one given to Localizer::Initialize (a sequence's first
  // odometry pose, what a robot would know; never ground truth).
  std::optional<Rigid3d> pose;
  // Pose init: standard deviations of the spread (m, degrees); with the
  // 6-DoF state they apply per axis.
  double spread_m = 0.05;
  double spread_deg = 3.0;
  // Global init and injection area (world x, y). Empty (min >= max): the
  // bounding box of the map's trajectory (or of its planes) grown by
  // area_margin_m.
  Eigen::Vector2d area_min = Eigen::Vector2d::Zero();
  Eigen::Vector2d area_max = Eigen::Vector2d::Zero();
  double area_margin_m = 0.2;

  void Check() const;
};

// The renderer localization compares live images with: the defaults, but
// each plane clipped to the part its landmarks support. Grown plain areas
// carry no pose information and flatten the likelihood (desk MCC 2.03 ->
// 2.44 mm with them; docs/design-notes.md, "Planes").
RendererOptions LocalizationRendererOptions();

struct LocalizerOptions {
  // Plain MCL, or MCL with Monte Carlo Correction of the best particles.
  LocalizationMethod method = LocalizationMethod::kMcl;
  // Planar: the state is the robot base (x, y, yaw) and the camera sits on
  // it through base_from_cam; 6-DoF: the state is world_from_cam.
  LocalizationState state = LocalizationState::kPlanar;
  MclOptions mcl;
  // The correction stage (method kMcc only).
  MccCorrectionOptions mcc;
  RecoveryOptions recovery;
  InitializationOptions init;
  RendererOptions renderer = LocalizationRendererOptions();
  uint64_t seed = 1;

  void Check() const;
};

struct LocalizerStepStats {
  int particles = 0;          // after resampling (or merging)
  int particles_weighed = 0;  // rendered this step
  double ess = 0.0;           // before resampling
  double max_weight = 0.0;    // normalized, before resampling
  double best_ncc = 0.0;
  // Share of the view the map covers, for the highest likelihood this
  // update (what the relocalization trigger judges by).
  double best_coverage = 0.0;
  double cluster_weight = 0.0;  // weight share of the estimate's cluster
  int kld_bins = 0;
  int injected = 0;
  bool relocalizing = false;  // the relocalization trigger holds (recovery.h)
  int mcc_attempted = 0;
  int mcc_accepted = 0;
  int merged = 0;
  bool refined = false;  // the estimate was refined (refine_estimate)
  bool resampled = false;
  double weigh_seconds = 0.0;  // rendering + NCC of every particle
  double mcc_seconds = 0.0;    // corrections (MCC only), refinement included
  double seconds = 0.0;        // the whole step
  // CPU time of the whole process during the step, all threads: the
  // share of cores the filter needs to keep up, whatever else runs.
  double cpu_seconds = 0.0;
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
  // Particles around world_from_cam with options' spread, or with the
  // given one (m, degrees; e.g. from rviz's "2D Pose Estimate").
  void InitializeAtPose(const Rigid3d& world_from_cam);
  void InitializeAtPose(const Rigid3d& world_from_cam, double spread_m,
                        double spread_deg);
  // The initialization options.init asks for. `odometry_pose` (a
  // sequence's first odometry pose): the start of a pose init without
  // options.init.pose, and the 6-DoF height and tilt reference of a global
  // init on a map without trajectory. Throws OptionsError for a pose init
  // without any pose.
  void Initialize(const std::optional<Rigid3d>& odometry_pose);

  // One filter update. `odometry` is ignored on the first step after
  // initialization. live_image_raw is the raw camera image.
  LocalizerEstimate Step(const cv::Mat& live_image_raw,
                         const OdometryIncrement& odometry);

  const std::vector<Particle>& particles() const { return particles_; }
  const Renderer& renderer() const { return renderer_; }
  const MeasurementModel& measurement() const { return measurement_; }
  // The area used by global init and injection.
  Eigen::Vector2d area_min() const { return area_.min; }
  Eigen::Vector2d area_max() const { return area_.max; }

 private:
  void Predict(const OdometryIncrement& odometry);
  std::vector<MeasurementScore> Weigh(const LiveFrame& live,
                                      LocalizerStepStats* stats);
  void Correct(const LiveFrame& live, std::vector<MeasurementScore>* scores,
               LocalizerStepStats* stats);
  LocalizerEstimate Estimate(const LiveFrame& live,
                             const std::vector<double>& weights,
                             LocalizerStepStats* stats) const;
  void Resample(const std::vector<double>& weights, LocalizerStepStats* stats);
  Particle RandomParticle();

  LocalizerOptions options_;
  Renderer renderer_;
  MeasurementModel measurement_;
  std::unique_ptr<StateModel> state_;
  std::unique_ptr<MccCorrection> correction_;  // method kMcc only
  RecoveryEstimator recovery_;
  LiveFrameSizes live_sizes_;
  bool map_has_trajectory_ = false;
  SamplingArea area_;
  std::vector<Particle> particles_;
  // 6-DoF: the pose random particles take height and tilt from.
  std::optional<Rigid3d> reference_;
  bool first_step_ = true;
  Rng rng_;
};

}  // namespace monomap
