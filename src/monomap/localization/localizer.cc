#include "monomap/localization/localizer.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "monomap/util/error.h"
#include "monomap/util/progress.h"

namespace monomap {

namespace {

constexpr double kDegToRad = M_PI / 180.0;

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

void LocalizerOptions::Check() const {
  CheckOption(num_particles >= 1, "num_particles", "must be >= 1");
  if (use_kld) kld.Check();
  noise2d.Check();
  noise6d.Check();
  measurement.Check();
  mcc.Check();
  refine_mcc.Check();
  renderer.Check();
  CheckOption(mcc_top_k >= 0, "mcc_top_k", "must be >= 0");
  CheckOption(mcc_spread_m >= 0, "mcc_spread_m", "must be >= 0");
  CheckOption(mcc_spread_deg >= 0, "mcc_spread_deg", "must be >= 0");
  CheckOption(merge_translation_m >= 0, "merge_translation_m", "must be >= 0");
  CheckOption(merge_rotation_deg >= 0, "merge_rotation_deg", "must be >= 0");
  CheckOption(resample_ess_fraction > 0 && resample_ess_fraction <= 1,
              "resample_ess_fraction", "must be in (0, 1]");
  CheckOption(injection_fraction >= 0 && injection_fraction < 1,
              "injection_fraction", "must be in [0, 1)");
  CheckOption(mcc_min_injected >= 0, "mcc_min_injected", "must be >= 0");
  CheckOption(relocalize_ncc_drop >= 0, "relocalize_ncc_drop", "must be >= 0");
  CheckOption(relocalize_fraction >= 0 && relocalize_fraction < 1,
              "relocalize_fraction", "must be in [0, 1)");
  CheckOption(relocalize_alpha_fast > 0 && relocalize_alpha_fast <= 1,
              "relocalize_alpha_fast", "must be in (0, 1]");
  CheckOption(relocalize_alpha_slow > 0 &&
                  relocalize_alpha_slow < relocalize_alpha_fast,
              "relocalize_alpha_slow", "must be in (0, relocalize_alpha_fast)");
  CheckOption(init_spread_m >= 0, "init_spread_m", "must be >= 0");
  CheckOption(init_spread_deg >= 0, "init_spread_deg", "must be >= 0");
  CheckOption(area_margin_m >= 0, "area_margin_m", "must be >= 0");
  CheckOption(cluster_radius_m > 0, "cluster_radius_m", "must be > 0");
  CheckOption(cluster_angle_deg > 0, "cluster_angle_deg", "must be > 0");
}

namespace {

// refine_mcc at the live camera's aspect, never larger than the camera:
// upsampling the live image would only blur the tracks.
MccOptions RefinementOptions(const LocalizerOptions& options,
                             const Camera& camera) {
  MccOptions o = options.refine_mcc;
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

Localizer::Localizer(const Map& map, const Camera& camera,
                     const LocalizerOptions& options,
                     const std::optional<Rigid3d>& base_from_cam)
    : options_(options),
      camera_(camera),
      base_from_cam_(base_from_cam),
      renderer_((options.Check(), map), options.renderer),
      measurement_(&renderer_, camera, options.measurement),
      corrector_(&renderer_, camera, options.mcc),
      refiner_(&renderer_, camera, RefinementOptions(options, camera)),
      rng_(options.seed) {
  if (options_.state == LocalizationState::kPlanar && !base_from_cam_) {
    throw OptionsError("state: planar needs base_from_cam (camera mount)");
  }
  if (renderer_.num_planes() == 0) {
    throw InputError("localization: the map has no textured plane");
  }
  for (const TimedPose& p : map.trajectory) {
    map_trajectory_.push_back(p.world_from_cam);
  }
  if (options_.area_min.x() < options_.area_max.x() &&
      options_.area_min.y() < options_.area_max.y()) {
    area_min_ = options_.area_min;
    area_max_ = options_.area_max;
  } else {
    Eigen::Vector2d lo = Eigen::Vector2d::Constant(1e300);
    Eigen::Vector2d hi = -lo;
    auto add = [&](const Eigen::Vector3d& x) {
      lo = lo.cwiseMin(x.head<2>());
      hi = hi.cwiseMax(x.head<2>());
    };
    for (const Rigid3d& p : map_trajectory_) add(p.translation);
    if (map_trajectory_.empty()) {
      for (const TexturedPlane& plane : map.planes) {
        for (const Eigen::Vector2d& st : plane.polygon) {
          add(plane.frame.ToWorld(st));
        }
      }
    }
    if (!(lo.x() <= hi.x())) {
      throw InputError("localization: the map has neither trajectory nor "
                       "plane polygons to bound the area");
    }
    area_min_ = lo.array() - options_.area_margin_m;
    area_max_ = hi.array() + options_.area_margin_m;
  }
}

void Localizer::SetPoseFromBase(Particle* p) const {
  p->world_from_cam = WorldFromCamOfBase(p->base, *base_from_cam_);
}

Particle Localizer::RandomParticle() {
  std::uniform_real_distribution<double> ux(area_min_.x(), area_max_.x());
  std::uniform_real_distribution<double> uy(area_min_.y(), area_max_.y());
  std::uniform_real_distribution<double> uyaw(-M_PI, M_PI);
  Particle p;
  if (options_.state == LocalizationState::kPlanar) {
    p.base = {ux(rng_), uy(rng_), uyaw(rng_)};
    SetPoseFromBase(&p);
    return p;
  }
  Rigid3d ref = global_reference_;
  if (!has_reference_) {
    if (map_trajectory_.empty()) {
      throw StageError("6-DoF global init needs a reference pose or a map "
                       "trajectory for the camera height and tilt");
    }
    std::uniform_int_distribution<size_t> pick(0, map_trajectory_.size() - 1);
    ref = map_trajectory_[pick(rng_)];
  }
  // Keep height, roll and pitch of the reference; draw x, y and yaw.
  const Eigen::Quaterniond q = YawRotation(uyaw(rng_)) * ref.rotation;
  p.world_from_cam =
      Rigid3d(q, Eigen::Vector3d(ux(rng_), uy(rng_), ref.translation.z()));
  return p;
}

void Localizer::InitializeGlobal(const std::optional<Rigid3d>& reference) {
  has_reference_ = reference.has_value();
  if (reference) global_reference_ = *reference;
  particles_.clear();
  for (int i = 0; i < options_.num_particles; ++i) {
    particles_.push_back(RandomParticle());
  }
  first_step_ = true;
  has_best_average_ = false;
}

void Localizer::InitializeAtPose(const Rigid3d& world_from_cam) {
  if (!has_reference_) {
    // Injection in 6-DoF keeps the height and tilt of this pose.
    global_reference_ = world_from_cam;
    has_reference_ = true;
  }
  particles_.clear();
  std::normal_distribution<double> dt(0.0, options_.init_spread_m);
  std::normal_distribution<double> dr(0.0,
                                      options_.init_spread_deg * kDegToRad);
  auto draw = [](std::normal_distribution<double>& d, Rng& r) {
    return d.stddev() > 0 ? d(r) : 0.0;
  };
  for (int i = 0; i < options_.num_particles; ++i) {
    Particle p;
    if (options_.state == LocalizationState::kPlanar) {
      const Pose2d b = BaseOfWorldFromCam(world_from_cam, *base_from_cam_);
      p.base = {b.x + draw(dt, rng_), b.y + draw(dt, rng_),
                WrapAngle(b.yaw + draw(dr, rng_))};
      SetPoseFromBase(&p);
    } else {
      Eigen::Vector3d v, w;
      for (int k = 0; k < 3; ++k) v[k] = draw(dt, rng_);
      for (int k = 0; k < 3; ++k) w[k] = draw(dr, rng_);
      p.world_from_cam =
          Rigid3d(QuaternionFromRotationVector(w) * world_from_cam.rotation,
                  world_from_cam.translation + v);
    }
    particles_.push_back(p);
  }
  first_step_ = true;
  has_best_average_ = false;
}

void Localizer::Initialize(const std::optional<Rigid3d>& pose) {
  if (options_.init == LocalizationInit::kGlobal) {
    InitializeGlobal();
    return;
  }
  if (!pose) throw OptionsError("init: pose needs a pose to start from");
  InitializeAtPose(*pose);
}

LocalizerEstimate Localizer::Step(const cv::Mat& live_image_raw,
                                  const OdometryIncrement& odometry) {
  if (particles_.empty()) {
    throw StageError("localizer: Step before Initialize");
  }
  const Timer timer;
  LocalizerStepStats stats;
  const bool planar = options_.state == LocalizationState::kPlanar;
  const cv::Mat undistorted = measurement_.preparer().Undistort(live_image_raw);
  const cv::Mat live_small = measurement_.PrepareLiveFromUndistorted(
      undistorted);

  // Predict.
  if (!first_step_) {
    for (Particle& p : particles_) {
      if (planar) {
        p.base = SampleOdometryMotion2d(p.base, odometry.base_prev,
                                        odometry.base_cur, options_.noise2d,
                                        &rng_);
        SetPoseFromBase(&p);
      } else {
        p.world_from_cam = SampleOdometryMotion6d(
            p.world_from_cam, odometry.cam_prev_from_cam_cur,
            options_.noise6d, &rng_);
      }
    }
  }
  first_step_ = false;

  // Weigh.
  const Timer weigh_timer;
  std::vector<Rigid3d> poses(particles_.size());
  for (size_t i = 0; i < particles_.size(); ++i) {
    poses[i] = particles_[i].world_from_cam;
  }
  std::vector<MeasurementScore> scores =
      measurement_.ScoreBatch(live_small, poses);
  stats.particles_weighed = static_cast<int>(particles_.size());
  for (size_t i = 0; i < particles_.size(); ++i) {
    particles_[i].log_weight += scores[i].log_likelihood;
  }
  stats.weigh_seconds = weigh_timer.ElapsedSeconds();

  // Correct the heaviest particles (before resampling, so that resampling
  // sees their corrected weights).
  if (options_.method == LocalizationMethod::kMcc && options_.mcc_top_k > 0) {
    const Timer mcc_timer;
    const std::vector<size_t> order = SpreadHeaviest(
        particles_, static_cast<size_t>(options_.mcc_top_k),
        options_.mcc_spread_m, options_.mcc_spread_deg * kDegToRad);
    const size_t k = order.size();
    const cv::Mat live_mid = LiveImagePreparer::Downscale(
        undistorted, options_.mcc.width, options_.mcc.height);
    std::vector<int> accepted(k, 0);
    tbb::parallel_for(size_t{0}, k, [&](size_t j) {
      Particle& p = particles_[order[j]];
      const MccResult r = corrector_.Correct(live_mid, p.world_from_cam);
      if (!r.accepted) return;
      Particle q = p;
      if (planar) {
        q.base = BaseOfWorldFromCam(r.world_from_cam, *base_from_cam_);
        SetPoseFromBase(&q);
      } else {
        q.world_from_cam = r.world_from_cam;
      }
      const MeasurementScore s = measurement_.Score(live_small,
                                                    q.world_from_cam);
      // Keep the correction only if the image agrees at least as well.
      if (s.log_likelihood < scores[order[j]].log_likelihood) return;
      q.log_weight += s.log_likelihood - scores[order[j]].log_likelihood;
      scores[order[j]] = s;
      p = q;
      accepted[j] = 1;
    });
    stats.mcc_attempted = static_cast<int>(k);
    stats.mcc_accepted = std::accumulate(accepted.begin(), accepted.end(), 0);
    stats.mcc_seconds = mcc_timer.ElapsedSeconds();
  }

  const std::vector<double> weights = NormalizedWeights(particles_);
  stats.ess = EffectiveSampleSize(weights);
  const size_t best = static_cast<size_t>(
      std::max_element(weights.begin(), weights.end()) - weights.begin());
  stats.max_weight = weights[best];
  stats.best_ncc = scores[best].ncc;

  LocalizerEstimate estimate;
  estimate.world_from_cam = BestClusterMean(
      particles_, weights, options_.cluster_radius_m,
      options_.cluster_angle_deg * kDegToRad, &stats.cluster_weight);
  if (planar) {
    estimate.base = BaseOfWorldFromCam(estimate.world_from_cam,
                                       *base_from_cam_);
    // The mean of camera poses of a planar state is (nearly) planar; put it
    // back exactly on the state manifold.
    estimate.world_from_cam = WorldFromCamOfBase(estimate.base,
                                                 *base_from_cam_);
  }

  if (options_.method == LocalizationMethod::kMcc && options_.refine_estimate) {
    const Timer refine_timer;
    const cv::Mat live_large = LiveImagePreparer::Downscale(
        undistorted, refiner_.options().width, refiner_.options().height);
    const MccResult r = refiner_.Correct(live_large, estimate.world_from_cam);
    if (r.accepted) {
      estimate.world_from_cam = r.world_from_cam;
      if (planar) {
        estimate.base = BaseOfWorldFromCam(r.world_from_cam, *base_from_cam_);
        estimate.world_from_cam =
            WorldFromCamOfBase(estimate.base, *base_from_cam_);
      }
      stats.refined = true;
    }
    stats.mcc_seconds += refine_timer.ElapsedSeconds();
  }

  // Relocalization: fast and slow averages of the best log-likelihood.
  int n_relocalize = 0;
  if (options_.relocalize_ncc_drop > 0) {
    double best_log = -std::numeric_limits<double>::infinity();
    for (const MeasurementScore& s : scores) {
      best_log = std::max(best_log, s.log_likelihood);
    }
    if (!has_best_average_) {
      best_fast_ = best_slow_ = best_log;
      has_best_average_ = true;
    } else {
      best_fast_ += options_.relocalize_alpha_fast * (best_log - best_fast_);
      best_slow_ += options_.relocalize_alpha_slow * (best_log - best_slow_);
    }
    const double drop =
        options_.relocalize_ncc_drop / options_.measurement.sigma;
    if (best_fast_ < best_slow_ - drop) {
      stats.relocalizing = true;
      n_relocalize = static_cast<int>(
          std::lround(options_.relocalize_fraction * options_.num_particles));
    }
  }

  // Resample.
  if (stats.ess < options_.resample_ess_fraction * particles_.size() + 1e-9) {
    std::vector<int> idx;
    if (options_.use_kld) {
      idx = KldResample(particles_, weights, options_.kld, planar, &rng_,
                        &stats.kld_bins);
    } else {
      idx = LowVarianceResample(weights, options_.num_particles, &rng_);
    }
    std::vector<Particle> next;
    next.reserve(idx.size());
    for (int i : idx) {
      next.push_back(particles_[i]);
      next.back().log_weight = 0.0;
    }
    int n_inject = static_cast<int>(
        std::lround(options_.injection_fraction * next.size()));
    if (options_.method == LocalizationMethod::kMcc) {
      // Never more than half the set: the resampled particles carry the
      // filter's belief.
      n_inject = std::max(
          n_inject, std::min(options_.mcc_min_injected,
                             static_cast<int>(next.size()) / 2));
    }
    std::uniform_int_distribution<size_t> pick(0, next.size() - 1);
    for (int i = 0; i < n_inject; ++i) next[pick(rng_)] = RandomParticle();
    // Relocalization adds to the set up to the budget, and replaces
    // (at most half of the set) beyond it.
    const int n_append = std::min(
        n_relocalize,
        std::max(0, options_.num_particles - static_cast<int>(next.size())));
    const int n_replace =
        std::min(n_relocalize - n_append, static_cast<int>(next.size()) / 2);
    for (int i = 0; i < n_replace; ++i) next[pick(rng_)] = RandomParticle();
    for (int i = 0; i < n_append; ++i) next.push_back(RandomParticle());
    stats.injected = n_inject + n_replace + n_append;
    particles_ = std::move(next);
    stats.resampled = true;
    if (options_.method == LocalizationMethod::kMcc) {
      stats.merged = MergeDuplicateParticles(
          &particles_, options_.merge_translation_m,
          options_.merge_rotation_deg * kDegToRad);
    }
  } else {
    // Keep log weights near 0 so they never overflow.
    const double max_log = particles_[best].log_weight;
    for (Particle& p : particles_) p.log_weight -= max_log;
  }
  stats.particles = static_cast<int>(particles_.size());
  stats.seconds = timer.ElapsedSeconds();
  estimate.stats = stats;
  return estimate;
}

LocalizationReport LocalizeSequence(
    const Map& map, const Dataset& dataset, const LocalizerOptions& options,
    std::vector<TimedPose>* trajectory,
    std::vector<std::vector<Particle>>* particle_sets) {
  options.Check();
  if (dataset.frames.empty()) throw InputError("localization: no frames");
  const bool planar = options.state == LocalizationState::kPlanar;
  if (planar) {
    // 2D odometry first: the mount is read only along with it.
    for (const DatasetFrame& f : dataset.frames) {
      if (!f.odometry_base) {
        throw InputError(dataset.root.string(), "odometry2d.txt",
                         "the planar state needs 2D odometry for every frame "
                         "(or use --state 6dof)");
      }
    }
    if (!dataset.base_from_cam) {
      throw InputError(dataset.root.string(), "camera_mount.yaml",
                       "the planar state needs the camera mount");
    }
  }
  const Timer timer;
  Localizer localizer(map, dataset.camera, options, dataset.base_from_cam);
  const DatasetFrame& first = dataset.frames.front();
  const Rigid3d start =
      options.init_pose.value_or(first.odometry_world_from_cam);
  if (options.init == LocalizationInit::kGlobal) {
    localizer.InitializeGlobal(
        map.trajectory.empty() ? std::optional<Rigid3d>(
                                     first.odometry_world_from_cam)
                               : std::nullopt);
  } else {
    localizer.InitializeAtPose(start);
  }

  LocalizationReport report;
  if (trajectory) trajectory->clear();
  if (particle_sets) particle_sets->clear();
  double sum_sq = 0.0, sum_rot = 0.0;
  int within = 0, with_gt = 0;
  ProgressBar progress("localize", dataset.frames.size());
  for (size_t i = 0; i < dataset.frames.size(); ++i) {
    const DatasetFrame& f = dataset.frames[i];
    OdometryIncrement odo;
    if (i > 0) {
      const DatasetFrame& prev = dataset.frames[i - 1];
      odo.cam_prev_from_cam_cur =
          prev.odometry_world_from_cam.Inverse() * f.odometry_world_from_cam;
      if (planar) {
        odo.base_prev = *prev.odometry_base;
        odo.base_cur = *f.odometry_base;
      }
    }
    const LocalizerEstimate e = localizer.Step(dataset.LoadImage(i), odo);
    if (trajectory) trajectory->push_back({f.timestamp, e.world_from_cam});
    if (particle_sets) particle_sets->push_back(localizer.particles());
    report.steps.push_back(e.stats);
    report.mean_step_seconds += e.stats.seconds;
    report.mean_particles += e.stats.particles;
    report.mcc_accepted += e.stats.mcc_accepted;
    if (f.groundtruth_world_from_cam) {
      const Rigid3d& gt = *f.groundtruth_world_from_cam;
      const double et = (gt.translation - e.world_from_cam.translation).norm();
      const double er =
          AngleBetween(gt.rotation, e.world_from_cam.rotation) / kDegToRad;
      sum_sq += et * et;
      sum_rot += er;
      within += et < 0.1 ? 1 : 0;
      ++with_gt;
      report.final_translation_error_m = et;
      report.final_rotation_error_deg = er;
    }
    progress.Advance();
  }
  progress.Finish();
  report.frames = static_cast<int>(dataset.frames.size());
  report.mean_step_seconds /= report.frames;
  report.mean_particles /= report.frames;
  if (with_gt > 0) {
    report.has_errors = true;
    report.rmse_translation_m = std::sqrt(sum_sq / with_gt);
    report.mean_rotation_error_deg = sum_rot / with_gt;
    report.fraction_within_10cm = static_cast<double>(within) / with_gt;
  }
  report.seconds = timer.ElapsedSeconds();
  return report;
}

}  // namespace monomap
