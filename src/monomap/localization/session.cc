#include "monomap/localization/session.h"

#include <chrono>
#include <cmath>

#include "monomap/util/angles.h"
#include "monomap/util/error.h"
#include "monomap/util/progress.h"

namespace monomap {

namespace {

double NowSeconds() {
  return std::chrono::duration<double>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

bool IsFinite(const Rigid3d& pose) {
  return pose.translation.allFinite() && pose.rotation.coeffs().allFinite();
}

OdometryIncrement IncrementBetween(const SessionFrame& prev,
                                   const SessionFrame& cur, bool planar) {
  OdometryIncrement odometry;
  odometry.cam_prev_from_cam_cur =
      prev.odom_from_cam.Inverse() * cur.odom_from_cam;
  if (planar) {
    odometry.base_prev = *prev.odom_base;
    odometry.base_cur = *cur.odom_base;
  }
  return odometry;
}

}  // namespace

void SessionOptions::Check() const {
  localizer.Check();
  CheckOption(max_pending_frames >= 1, "max_pending_frames", "must be >= 1");
  CheckOption(lost_after_updates >= 1, "lost_after_updates", "must be >= 1");
  CheckOption(min_stamp_step_s >= 0, "min_stamp_step_s", "must be >= 0");
}

std::string ToString(SessionStatus status) {
  switch (status) {
    case SessionStatus::kTracking:
      return "tracking";
    case SessionStatus::kRelocalizing:
      return "relocalizing";
    case SessionStatus::kLost:
      return "lost";
  }
  return "unknown";
}

Eigen::Matrix<double, 6, 6> PoseCovariance(
    const std::vector<Rigid3d>& world_from_x, const std::vector<double>& weights,
    const Rigid3d& center) {
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  double total = 0.0;
  for (size_t i = 0; i < world_from_x.size(); ++i) {
    Eigen::Matrix<double, 6, 1> d;
    d.head<3>() = world_from_x[i].translation - center.translation;
    // The rotation that takes the centre to the particle, about world axes.
    const Eigen::AngleAxisd delta(world_from_x[i].rotation *
                                  center.rotation.conjugate());
    d.tail<3>() = delta.angle() * delta.axis();
    covariance += weights[i] * d * d.transpose();
    total += weights[i];
  }
  if (total > 0) covariance /= total;
  return covariance;
}

LocalizationSession::LocalizationSession(
    std::shared_ptr<const Map> map, const Camera& live_camera,
    const SessionOptions& options, const std::optional<Rigid3d>& base_from_cam)
    : map_((options.Check(), std::move(map))),
      live_camera_(live_camera),
      options_(options),
      base_from_cam_(base_from_cam),
      localizer_(*map_, live_camera, options.localizer, base_from_cam) {}

LocalizationSession::~LocalizationSession() { Stop(); }

std::string LocalizationSession::CheckFrame(const SessionFrame& frame) const {
  if (!std::isfinite(frame.stamp)) return "the stamp is not finite";
  if (frame.image.empty()) return "the image is empty";
  if (frame.image.cols != live_camera_.width ||
      frame.image.rows != live_camera_.height) {
    return "the image is " + std::to_string(frame.image.cols) + "x" +
           std::to_string(frame.image.rows) + ", the camera " +
           std::to_string(live_camera_.width) + "x" +
           std::to_string(live_camera_.height);
  }
  if (!IsFinite(frame.odom_from_cam)) return "the odometry is not finite";
  if (options_.localizer.state == LocalizationState::kPlanar &&
      !frame.odom_base) {
    return "the planar state needs the base's planar odometry";
  }
  std::lock_guard<std::mutex> lock(mutex_);
  if (last_stamp_ && frame.stamp < *last_stamp_ + options_.min_stamp_step_s) {
    return "stamp " + std::to_string(frame.stamp) +
           " s is not after the previous frame's " +
           std::to_string(*last_stamp_) + " s";
  }
  return "";
}

void LocalizationSession::ApplyRequests(const SessionFrame& frame) {
  std::vector<Request> requests;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    requests.swap(requests_);
  }
  if (!initialized_) {
    localizer_.Initialize(frame.odom_from_cam);
    initialized_ = true;
  }
  for (const Request& r : requests) {
    if (r.global) {
      // As Localizer::Initialize: 6-DoF height and tilt from the map's
      // poses, or from the odometry on a map without any.
      localizer_.InitializeGlobal(
          map_->trajectory.empty() ? std::optional(frame.odom_from_cam)
                                   : std::nullopt);
    } else {
      localizer_.InitializeAtPose(r.world_from_cam, r.spread_m, r.spread_deg);
    }
    relocalizing_run_ = 0;
  }
}

Eigen::Matrix<double, 6, 6> LocalizationSession::ClusterCovariance(
    const Rigid3d& world_from_cam, const Rigid3d& cam_from_base) const {
  const std::vector<Particle>& particles = localizer_.particles();
  const std::vector<double> all_weights = NormalizedWeights(particles);
  const MclOptions& mcl = options_.localizer.mcl;
  std::vector<Rigid3d> poses;
  std::vector<double> weights;
  for (size_t i = 0; i < particles.size(); ++i) {
    const Rigid3d& p = particles[i].world_from_cam;
    if ((p.translation - world_from_cam.translation).norm() >
            mcl.cluster_radius_m ||
        AngleBetween(p.rotation, world_from_cam.rotation) >
            DegToRad(mcl.cluster_angle_deg)) {
      continue;
    }
    poses.push_back(p * cam_from_base);
    weights.push_back(all_weights[i]);
  }
  return PoseCovariance(poses, weights, world_from_cam * cam_from_base);
}

SessionResult LocalizationSession::Update(const SessionFrame& frame) {
  const Timer timer;
  ApplyRequests(frame);
  const OdometryIncrement odometry =
      previous_ ? IncrementBetween(*previous_, frame,
                                   options_.localizer.state ==
                                       LocalizationState::kPlanar)
                : OdometryIncrement();
  const LocalizerEstimate e = localizer_.Step(frame.image, odometry);
  previous_ = frame;
  previous_->image = cv::Mat();  // only its odometry is needed

  SessionResult r;
  r.stamp = frame.stamp;
  r.world_from_cam = e.world_from_cam;
  r.odom_from_cam = frame.odom_from_cam;
  r.stats = e.stats;
  relocalizing_run_ = e.stats.relocalizing ? relocalizing_run_ + 1 : 0;
  r.status = relocalizing_run_ == 0 ? SessionStatus::kTracking
             : relocalizing_run_ >= options_.lost_after_updates
                 ? SessionStatus::kLost
                 : SessionStatus::kRelocalizing;
  const Rigid3d cam_from_base =
      base_from_cam_ ? base_from_cam_->Inverse() : Rigid3d::Identity();
  if (base_from_cam_) r.world_from_base = e.world_from_cam * cam_from_base;
  r.covariance = ClusterCovariance(e.world_from_cam, cam_from_base);
  if (options_.output_particles) r.particles = localizer_.particles();
  r.latency_seconds = timer.ElapsedSeconds();
  return r;
}

SessionResult LocalizationSession::Process(const SessionFrame& frame) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (running_) throw StageError("session: Process() while Start()ed");
    ++counters_.received;
  }
  const std::string problem = CheckFrame(frame);
  if (!problem.empty()) {
    std::lock_guard<std::mutex> lock(mutex_);
    ++counters_.rejected;
    throw InputError("frame at " + std::to_string(frame.stamp) +
                     " s: " + problem);
  }
  std::lock_guard<std::mutex> update_lock(update_mutex_);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    last_stamp_ = frame.stamp;
  }
  SessionResult r = Update(frame);
  std::lock_guard<std::mutex> lock(mutex_);
  r.frames_processed = ++counters_.processed;
  r.frames_dropped = counters_.dropped;
  last_result_ = r;
  return r;
}

void LocalizationSession::Start(ResultCallback on_result) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (running_) throw StageError("session: Start() while running");
  on_result_ = std::move(on_result);
  running_ = true;
  stopping_ = false;
  worker_ = std::thread([this] { WorkerLoop(); });
}

PushOutcome LocalizationSession::Push(SessionFrame frame) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++counters_.received;
    if (!running_) {
      ++counters_.rejected;
      return {false, "the session is not started"};
    }
  }
  const std::string problem = CheckFrame(frame);
  std::unique_lock<std::mutex> lock(mutex_);
  if (!problem.empty()) {
    ++counters_.rejected;
    return {false, problem};
  }
  last_stamp_ = frame.stamp;
  const size_t room = static_cast<size_t>(options_.max_pending_frames);
  if (!options_.drop_when_busy) {
    cv_.wait(lock, [&] { return pending_.size() < room || stopping_; });
  }
  while (pending_.size() >= room) {
    pending_.pop_front();
    ++counters_.dropped;
  }
  pending_.emplace_back(std::move(frame), NowSeconds());
  cv_.notify_all();
  return {true, ""};
}

void LocalizationSession::WorkerLoop() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    cv_.wait(lock, [&] { return stopping_ || !pending_.empty(); });
    if (stopping_) break;
    auto [frame, pushed_at] = std::move(pending_.front());
    pending_.pop_front();
    busy_ = true;
    cv_.notify_all();  // room for a blocked Push()
    lock.unlock();
    SessionResult r;
    {
      std::lock_guard<std::mutex> update_lock(update_mutex_);
      r = Update(frame);
    }
    r.latency_seconds = NowSeconds() - pushed_at;
    lock.lock();
    r.frames_processed = ++counters_.processed;
    r.frames_dropped = counters_.dropped;
    last_result_ = r;
    lock.unlock();
    if (on_result_) on_result_(r);
    lock.lock();
    busy_ = false;
    cv_.notify_all();
  }
  busy_ = false;
  cv_.notify_all();
}

void LocalizationSession::Flush() {
  std::unique_lock<std::mutex> lock(mutex_);
  cv_.wait(lock, [&] { return !running_ || (pending_.empty() && !busy_); });
}

void LocalizationSession::Stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!running_) return;
    stopping_ = true;
    counters_.dropped += static_cast<int64_t>(pending_.size());
    pending_.clear();
  }
  cv_.notify_all();
  worker_.join();
  std::lock_guard<std::mutex> lock(mutex_);
  running_ = false;
  stopping_ = false;
  cv_.notify_all();
}

void LocalizationSession::SetPose(const Rigid3d& world_from_cam,
                                  std::optional<double> spread_m,
                                  std::optional<double> spread_deg) {
  Request r;
  r.world_from_cam = world_from_cam;
  r.spread_m = spread_m.value_or(options_.localizer.init.spread_m);
  r.spread_deg = spread_deg.value_or(options_.localizer.init.spread_deg);
  if (!IsFinite(world_from_cam) || !(r.spread_m >= 0) || !(r.spread_deg >= 0)) {
    throw OptionsError("session: SetPose needs a finite pose and spreads >= 0");
  }
  std::lock_guard<std::mutex> lock(mutex_);
  requests_.push_back(r);
}

void LocalizationSession::StartGlobalLocalization() {
  Request r;
  r.global = true;
  std::lock_guard<std::mutex> lock(mutex_);
  requests_.push_back(r);
}

SessionCounters LocalizationSession::counters() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return counters_;
}

std::optional<SessionResult> LocalizationSession::last_result() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return last_result_;
}

}  // namespace monomap
