// A streaming localization session: what a live robot (or a ROS node over
// it) uses. Frames come one at a time (image, stamp, odometry) and each
// processed frame gives a pose with covariance, the particle set and a
// status. The session knows nothing of ROS or of files: the caller owns
// transport and loading (pipelines/localization_pipeline.h opens one from
// a map directory).
//
// Two ways to drive it:
//  - Process(): synchronous, one frame in, one result out. Deterministic
//    given the seed; LocalizeSequence (what `monomap localize` runs) is this
//    loop, so a replay through Process gives the same trajectory.
//  - Start() + Push(): a worker thread processes frames while Push never
//    blocks (with drop_when_busy). At most max_pending_frames wait; a newer
//    frame replaces the oldest waiting one, which is counted as dropped.
//    Odometry increments span dropped frames, so dropping loses images,
//    never motion. Which frames are dropped depends on timing.
//
// Thread safety: every public method may be called from any thread. The
// result callback runs on the worker thread; it must not call Stop() or
// the destructor. Process() and Start() are exclusive: Process() throws
// StageError while the worker runs.
#pragma once

#include <Eigen/Core>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "monomap/geometry/pose2d.h"
#include "monomap/localization/localizer.h"
#include "monomap/map/map.h"

namespace monomap {

struct SessionOptions {
  // The filter (method, state, particles, initialization, ...). A pose
  // init without init.pose starts at the first frame's odometry pose.
  LocalizerOptions localizer;
  // Push() drops frames while the worker is busy (live use); false: Push()
  // blocks until there is room (offline replay without drops).
  bool drop_when_busy = true;
  // Frames that may wait for the worker; beyond, the oldest is dropped.
  int max_pending_frames = 1;
  // The status turns from relocalizing to lost after this many
  // consecutive relocalizing updates (about half a second at 30 fps).
  int lost_after_updates = 15;
  // Frames whose stamp is not later than the last accepted one by at least
  // this (s) are rejected (stamps going backwards or repeated).
  double min_stamp_step_s = 0.0;
  // Copy the particle set into every result (the node's PoseArray).
  bool output_particles = true;

  void Check() const;
};

// One camera frame with the robot's odometry at the image's stamp.
struct SessionFrame {
  double stamp = 0.0;  // seconds
  // The raw (distorted) camera image, gray or BGR, of the live camera's
  // size.
  cv::Mat image;
  // The camera's pose in the odometry frame (odom_from_base *
  // base_from_cam); its increments drive the 6-DoF state.
  Rigid3d odom_from_cam;
  // The base's planar odometry pose (x, y, yaw in the odom frame); the
  // planar state needs it.
  std::optional<Pose2d> odom_base;
};

enum class SessionStatus {
  kTracking,      // the filter follows the measurements
  kRelocalizing,  // the trigger fired: random particles are being injected
  kLost,          // relocalizing for lost_after_updates updates in a row
};
std::string ToString(SessionStatus status);

struct SessionResult {
  double stamp = 0.0;
  SessionStatus status = SessionStatus::kTracking;
  Rigid3d world_from_cam;
  // With a camera mount: the base pose in the map (world) frame.
  std::optional<Rigid3d> world_from_base;
  // The odometry the frame came with, so that a caller can publish
  // world_from_odom = world_from_cam * odom_from_cam^-1.
  Rigid3d odom_from_cam;
  // Covariance about the estimate of the particles in its cluster (within
  // mcl.cluster_radius_m and cluster_angle_deg; random injected particles
  // elsewhere would swamp it), of the base pose if there is a mount, else
  // of the camera pose: (x, y, z, then rotation about the world's x, y, z
  // axes in rad), as in ROS's PoseWithCovariance. MCC merges its set to a
  // few particles, so there it is a lower bound.
  Eigen::Matrix<double, 6, 6> covariance =
      Eigen::Matrix<double, 6, 6>::Zero();
  std::vector<Particle> particles;  // empty without output_particles
  LocalizerStepStats stats;
  // Push() to result (threaded), or the processing time (Process()).
  double latency_seconds = 0.0;
  // Counters at the time of this result.
  int64_t frames_dropped = 0;
  int64_t frames_processed = 0;
};

struct SessionCounters {
  int64_t received = 0;   // frames given to Push() or Process()
  int64_t rejected = 0;   // bad frames (see SessionFrameError)
  int64_t dropped = 0;    // replaced while waiting for the worker
  int64_t processed = 0;  // frames that gave a result
};

// Why a frame is refused; empty when it is fine.
struct PushOutcome {
  bool accepted = false;
  std::string reason;  // one line, for a log (empty when accepted)
};

class LocalizationSession {
 public:
  using ResultCallback = std::function<void(const SessionResult&)>;

  // `live_camera`: the camera the images come from (with distortion).
  // `base_from_cam`: the camera mount; the planar state needs it. Throws
  // OptionsError on bad options.
  LocalizationSession(std::shared_ptr<const Map> map, const Camera& live_camera,
                      const SessionOptions& options,
                      const std::optional<Rigid3d>& base_from_cam = {});
  ~LocalizationSession();  // stops the worker
  LocalizationSession(const LocalizationSession&) = delete;
  LocalizationSession& operator=(const LocalizationSession&) = delete;

  // Synchronous update. Throws InputError for a frame Push() would reject.
  SessionResult Process(const SessionFrame& frame);

  // Starts the worker; each result goes to `on_result` (on the worker).
  void Start(ResultCallback on_result);
  // Queues a frame for the worker (see drop_when_busy). Never throws for a
  // bad frame: it is refused with the reason.
  PushOutcome Push(SessionFrame frame);
  // Waits until every queued frame is processed.
  void Flush();
  // Stops the worker after the frame in progress; queued frames are
  // dropped. Start() may be called again.
  void Stop();

  // Requests that take effect before the next frame (rviz's "2D Pose
  // Estimate", a global-localization service). The spreads default to the
  // init options'.
  void SetPose(const Rigid3d& world_from_cam,
               std::optional<double> spread_m = {},
               std::optional<double> spread_deg = {});
  void StartGlobalLocalization();

  SessionCounters counters() const;
  // The last result, if any frame was processed.
  std::optional<SessionResult> last_result() const;
  const Camera& live_camera() const { return live_camera_; }
  const SessionOptions& options() const { return options_; }

 private:
  // A pose or global request, applied before the next update.
  struct Request {
    bool global = false;
    Rigid3d world_from_cam;
    double spread_m = 0.0, spread_deg = 0.0;
  };
  std::string CheckFrame(const SessionFrame& frame) const;
  SessionResult Update(const SessionFrame& frame);
  Eigen::Matrix<double, 6, 6> ClusterCovariance(
      const Rigid3d& world_from_cam, const Rigid3d& cam_from_base) const;
  void ApplyRequests(const SessionFrame& frame);
  void WorkerLoop();

  std::shared_ptr<const Map> map_;
  Camera live_camera_;
  SessionOptions options_;
  std::optional<Rigid3d> base_from_cam_;

  // Owned by whoever holds update_mutex_ (the worker, or Process()).
  std::mutex update_mutex_;
  Localizer localizer_;
  bool initialized_ = false;
  std::optional<SessionFrame> previous_;  // odometry of the last update
  int relocalizing_run_ = 0;

  mutable std::mutex mutex_;  // guards everything below
  std::condition_variable cv_;
  std::optional<double> last_stamp_;  // of the last accepted frame
  std::vector<Request> requests_;
  std::deque<std::pair<SessionFrame, double>> pending_;  // frame, push time
  bool running_ = false;
  bool stopping_ = false;
  bool busy_ = false;
  ResultCallback on_result_;
  std::thread worker_;
  SessionCounters counters_;
  std::optional<SessionResult> last_result_;
};

// The particles' covariance about `center` (rotation as world-axis angles)
// for the poses `world_from_x` of every particle (x: base or camera).
Eigen::Matrix<double, 6, 6> PoseCovariance(
    const std::vector<Rigid3d>& world_from_x, const std::vector<double>& weights,
    const Rigid3d& center);

}  // namespace monomap
