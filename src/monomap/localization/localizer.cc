#include "monomap/localization/localizer.h"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <limits>

#include "monomap/util/angles.h"
#include "monomap/util/error.h"
#include "monomap/util/progress.h"

namespace monomap {

RendererOptions LocalizationRendererOptions() {
  RendererOptions options;
  options.clip_to_landmark_polygon = true;
  return options;
}

namespace {

// CPU seconds used by the process so far (all threads).
double ProcessCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

}  // namespace

LocalizationMethod ParseLocalizationMethod(const std::string& s) {
  if (s == "mcl") return LocalizationMethod::kMcl;
  if (s == "mcc") return LocalizationMethod::kMcc;
  throw OptionsError("method: '" + s + "' is not mcl or mcc");
}

LocalizationState ParseLocalizationState(const std::string& s) {
  if (s == "planar") return LocalizationState::kPlanar;
  if (s == "6dof") return LocalizationState::k6Dof;
  throw OptionsError("state: '" + s + "' is not planar or 6dof");
}

LocalizationInit ParseLocalizationInit(const std::string& s) {
  if (s == "global") return LocalizationInit::kGlobal;
  if (s == "pose") return LocalizationInit::kPose;
  throw OptionsError("init: '" + s + "' is not global or pose");
}

void MclOptions::SetParticleBudget(int particles) {
  num_particles = particles;
  kld.max_particles = particles;
  kld.min_particles = std::min(kld.min_particles, particles);
}

void MclOptions::Check() const {
  CheckOption(num_particles >= 1, "num_particles", "must be >= 1");
  if (use_kld) kld.Check();
  noise2d.Check();
  noise6d.Check();
  measurement.Check();
  CheckOption(resample_ess_fraction > 0 && resample_ess_fraction <= 1,
              "resample_ess_fraction", "must be in (0, 1]");
  CheckOption(cluster_radius_m > 0, "cluster_radius_m", "must be > 0");
  CheckOption(cluster_angle_deg > 0, "cluster_angle_deg", "must be > 0");
}

void InitializationOptions::Check() const {
  CheckOption(spread_m >= 0, "init_spread_m", "must be >= 0");
  CheckOption(spread_deg >= 0, "init_spread_deg", "must be >= 0");
  CheckOption(area_margin_m >= 0, "area_margin_m", "must be >= 0");
}

void LocalizerOptions::Check() const {
  mcl.Check();
  mcc.Check();
  recovery.Check();
  init.Check();
  renderer.Check();
}

namespace {

std::unique_ptr<StateModel> MakeStateModel(
    const Map& map, const LocalizerOptions& options,
    const std::optional<Rigid3d>& base_from_cam) {
  if (options.state == LocalizationState::kPlanar) {
    if (!base_from_cam) {
      throw OptionsError("state: planar needs base_from_cam (camera mount)");
    }
    return std::make_unique<PlanarStateModel>(*base_from_cam,
                                              options.mcl.noise2d);
  }
  std::vector<Rigid3d> trajectory;
  for (const TimedPose& p : map.trajectory) {
    trajectory.push_back(p.world_from_cam);
  }
  return std::make_unique<SixDofStateModel>(options.mcl.noise6d,
                                            std::move(trajectory));
}

// options' area, or the map's trajectory (else its planes) grown by the
// margin.
SamplingArea AreaOf(const Map& map, const InitializationOptions& options) {
  if (options.area_min.x() < options.area_max.x() &&
      options.area_min.y() < options.area_max.y()) {
    return {options.area_min, options.area_max};
  }
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(1e300);
  Eigen::Vector2d hi = -lo;
  auto add = [&](const Eigen::Vector3d& x) {
    lo = lo.cwiseMin(x.head<2>());
    hi = hi.cwiseMax(x.head<2>());
  };
  for (const TimedPose& p : map.trajectory) add(p.world_from_cam.translation);
  if (map.trajectory.empty()) {
    for (const TexturedPlane& plane : map.planes) {
      for (const Eigen::Vector2d& st : plane.polygon) {
        add(plane.frame.ToWorld(st));
      }
    }
  }
  if (!(lo.x() <= hi.x())) {
    throw InputError(
        "localization: the map has neither trajectory nor "
        "plane polygons to bound the area");
  }
  return {lo.array() - options.area_margin_m,
          hi.array() + options.area_margin_m};
}

// The score of the highest likelihood this update.
const MeasurementScore& BestScore(const std::vector<MeasurementScore>& scores) {
  return *std::max_element(
      scores.begin(), scores.end(),
      [](const MeasurementScore& a, const MeasurementScore& b) {
        return a.log_likelihood < b.log_likelihood;
      });
}

}  // namespace

Localizer::Localizer(const Map& map, const Camera& camera,
                     const LocalizerOptions& options,
                     const std::optional<Rigid3d>& base_from_cam)
    : options_(options),
      renderer_((options.Check(), map), options.renderer),
      measurement_(&renderer_, camera, options.mcl.measurement),
      state_(MakeStateModel(map, options, base_from_cam)),
      correction_(
          options.method == LocalizationMethod::kMcc
              ? std::make_unique<MccCorrection>(&renderer_, camera, options.mcc)
              : nullptr),
      recovery_(options.recovery, options.method == LocalizationMethod::kMcc,
                options.mcl.num_particles),
      map_has_trajectory_(!map.trajectory.empty()),
      rng_(options.seed) {
  if (renderer_.num_planes() == 0) {
    throw InputError("localization: the map has no textured plane");
  }
  area_ = AreaOf(map, options_.init);
  live_sizes_.measurement = {options_.mcl.measurement.width,
                             options_.mcl.measurement.height};
  if (correction_) correction_->AddSizes(&live_sizes_);
}

Particle Localizer::RandomParticle() {
  return state_->Random(area_, reference_, &rng_);
}

void Localizer::InitializeGlobal(const std::optional<Rigid3d>& reference) {
  reference_ = reference;
  particles_.clear();
  for (int i = 0; i < options_.mcl.num_particles; ++i) {
    particles_.push_back(RandomParticle());
  }
  first_step_ = true;
  recovery_.Reset();
}

void Localizer::InitializeAtPose(const Rigid3d& world_from_cam) {
  InitializeAtPose(world_from_cam, options_.init.spread_m,
                   options_.init.spread_deg);
}

void Localizer::InitializeAtPose(const Rigid3d& world_from_cam, double spread_m,
                                 double spread_deg) {
  // Injection in 6-DoF keeps the height and tilt of this pose.
  if (!reference_) reference_ = world_from_cam;
  particles_ = state_->AroundPose(world_from_cam, options_.mcl.num_particles,
                                  spread_m, DegToRad(spread_deg), &rng_);
  first_step_ = true;
  recovery_.Reset();
}

void Localizer::Initialize(const std::optional<Rigid3d>& odometry_pose) {
  if (options_.init.kind == LocalizationInit::kGlobal) {
    // The 6-DoF height and tilt come from the map's poses if it has any.
    InitializeGlobal(map_has_trajectory_ ? std::nullopt : odometry_pose);
    return;
  }
  const std::optional<Rigid3d> start =
      options_.init.pose ? options_.init.pose : odometry_pose;
  if (!start) throw OptionsError("init: pose needs a pose to start from");
  InitializeAtPose(*start);
}

LocalizerEstimate Localizer::Step(const cv::Mat& live_image_raw,
                                  const OdometryIncrement& odometry) {
  if (particles_.empty()) {
    throw StageError("localizer: Step before Initialize");
  }
  const Timer timer;
  const double cpu_start = ProcessCpuSeconds();
  LocalizerStepStats stats;
  const LiveFrame live(live_image_raw, measurement_.preparer(), live_sizes_);
  Predict(odometry);
  std::vector<MeasurementScore> scores = Weigh(live, &stats);
  // Before resampling, so that resampling sees the corrected weights.
  if (correction_) Correct(live, &scores, &stats);

  const std::vector<double> weights = NormalizedWeights(particles_);
  const size_t best = static_cast<size_t>(
      std::max_element(weights.begin(), weights.end()) - weights.begin());
  stats.ess = EffectiveSampleSize(weights);
  stats.max_weight = weights[best];
  stats.best_ncc = scores[best].ncc;
  LocalizerEstimate estimate = Estimate(live, weights, &stats);

  const MeasurementScore& top = BestScore(scores);
  stats.best_coverage = top.coverage;
  stats.relocalizing = recovery_.Update(top.ncc, top.coverage);
  if (stats.ess <
      options_.mcl.resample_ess_fraction * particles_.size() + 1e-9) {
    Resample(weights, &stats);
  } else {
    // Keep log weights near 0 so they never overflow.
    const double max_log = particles_[best].log_weight;
    for (Particle& p : particles_) p.log_weight -= max_log;
  }
  stats.particles = static_cast<int>(particles_.size());
  stats.seconds = timer.ElapsedSeconds();
  stats.cpu_seconds = ProcessCpuSeconds() - cpu_start;
  estimate.stats = stats;
  return estimate;
}

void Localizer::Predict(const OdometryIncrement& odometry) {
  if (!first_step_) {
    for (Particle& p : particles_) state_->Predict(odometry, &rng_, &p);
  }
  first_step_ = false;
}

std::vector<MeasurementScore> Localizer::Weigh(const LiveFrame& live,
                                               LocalizerStepStats* stats) {
  const Timer weigh_timer;
  std::vector<Rigid3d> poses(particles_.size());
  for (size_t i = 0; i < particles_.size(); ++i) {
    poses[i] = particles_[i].world_from_cam;
  }
  std::vector<MeasurementScore> scores =
      measurement_.ScoreBatch(live.measurement(), poses);
  stats->particles_weighed = static_cast<int>(particles_.size());
  for (size_t i = 0; i < particles_.size(); ++i) {
    particles_[i].log_weight += scores[i].log_likelihood;
  }
  stats->weigh_seconds = weigh_timer.ElapsedSeconds();
  return scores;
}

void Localizer::Correct(const LiveFrame& live,
                        std::vector<MeasurementScore>* scores,
                        LocalizerStepStats* stats) {
  const Timer mcc_timer;
  const MccCorrectionStats c = correction_->CorrectParticles(
      live, measurement_, *state_, &particles_, scores);
  stats->mcc_attempted = c.attempted;
  stats->mcc_accepted = c.accepted;
  stats->mcc_seconds = mcc_timer.ElapsedSeconds();
}

LocalizerEstimate Localizer::Estimate(const LiveFrame& live,
                                      const std::vector<double>& weights,
                                      LocalizerStepStats* stats) const {
  // The mean of the camera poses of a planar state is (nearly) planar;
  // FromPose puts it back exactly on the state's manifold.
  Particle mean = state_->FromPose(BestClusterMean(
      particles_, weights, options_.mcl.cluster_radius_m,
      DegToRad(options_.mcl.cluster_angle_deg), &stats->cluster_weight));
  if (correction_) {
    const Timer refine_timer;
    stats->refined = correction_->RefineEstimate(live, *state_, &mean);
    stats->mcc_seconds += refine_timer.ElapsedSeconds();
  }
  LocalizerEstimate estimate;
  estimate.world_from_cam = mean.world_from_cam;
  estimate.base = mean.base;
  return estimate;
}

void Localizer::Resample(const std::vector<double>& weights,
                         LocalizerStepStats* stats) {
  const MclOptions& o = options_.mcl;
  std::vector<int> idx;
  if (o.use_kld) {
    idx = KldResample(
        particles_, weights, o.kld,
        [&](const Particle& p) { return state_->Bin(p, o.kld); }, &rng_,
        &stats->kld_bins);
  } else {
    idx = LowVarianceResample(weights, o.num_particles, &rng_);
  }
  std::vector<Particle> next;
  next.reserve(idx.size());
  for (int i : idx) {
    next.push_back(particles_[i]);
    next.back().log_weight = 0.0;
  }
  const InjectionPlan plan = recovery_.Plan(static_cast<int>(next.size()));
  std::uniform_int_distribution<size_t> pick(0, next.size() - 1);
  for (int i = 0; i < plan.replaced; ++i) next[pick(rng_)] = RandomParticle();
  for (int i = 0; i < plan.appended; ++i) next.push_back(RandomParticle());
  stats->injected = plan.replaced + plan.appended;
  particles_ = std::move(next);
  stats->resampled = true;
  if (correction_) stats->merged = correction_->MergeDuplicates(&particles_);
}

}  // namespace monomap
