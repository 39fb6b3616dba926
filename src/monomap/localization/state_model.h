// The state the filter estimates, chosen once per Localizer: planar (the
// robot base's x, y and yaw, the camera on it through base_from_cam) or
// 6-DoF (world_from_cam). Everything that differs between the two goes
// through StateModel: motion sampling, random and spread states, turning a
// camera pose into a state, and the KLD histogram bin.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <vector>

#include "monomap/geometry/pose2d.h"
#include "monomap/geometry/rigid3.h"
#include "monomap/localization/particle_filter.h"

namespace monomap {

// An odometry increment between the previous and the current frame.
struct OdometryIncrement {
  // 6-DoF: relative camera motion from odometry.txt poses.
  Rigid3d cam_prev_from_cam_cur;
  // Planar: odometry base poses of both frames (odometry2d.txt).
  Pose2d base_prev, base_cur;
};

// Where random states are drawn: world x, y uniform in [min, max].
struct SamplingArea {
  Eigen::Vector2d min = Eigen::Vector2d::Zero();
  Eigen::Vector2d max = Eigen::Vector2d::Zero();
};

class StateModel {
 public:
  virtual ~StateModel() = default;

  // The particle (weight 0) whose state best explains a camera pose; its
  // world_from_cam lies on the state's manifold (planar: height, roll and
  // pitch come from the mount).
  virtual Particle FromPose(const Rigid3d& world_from_cam) const = 0;
  // Moves a particle by an odometry increment plus sampled noise.
  virtual void Predict(const OdometryIncrement& odometry, Rng* rng,
                       Particle* p) const = 0;
  // A state uniform over the area, yaw uniform. `reference` (6-DoF): the
  // pose whose height, roll and pitch the state keeps; without it, those
  // of a random map trajectory pose.
  virtual Particle Random(const SamplingArea& area,
                          const std::optional<Rigid3d>& reference,
                          Rng* rng) const = 0;
  // `n` states around a camera pose, normal with standard deviations
  // spread_m and spread_rad (per axis with the 6-DoF state).
  virtual std::vector<Particle> AroundPose(const Rigid3d& world_from_cam, int n,
                                           double spread_m, double spread_rad,
                                           Rng* rng) const = 0;
  // The particle's cell of the KLD-sampling histogram.
  virtual KldBin Bin(const Particle& p, const KldOptions& options) const = 0;
};

// x, y, yaw of the robot base; world_from_cam follows through the mount.
class PlanarStateModel : public StateModel {
 public:
  PlanarStateModel(const Rigid3d& base_from_cam, const OdometryNoise2d& noise)
      : base_from_cam_(base_from_cam), noise_(noise) {}

  Particle FromPose(const Rigid3d& world_from_cam) const override;
  void Predict(const OdometryIncrement& odometry, Rng* rng,
               Particle* p) const override;
  Particle Random(const SamplingArea& area,
                  const std::optional<Rigid3d>& reference,
                  Rng* rng) const override;
  std::vector<Particle> AroundPose(const Rigid3d& world_from_cam, int n,
                                   double spread_m, double spread_rad,
                                   Rng* rng) const override;
  KldBin Bin(const Particle& p, const KldOptions& options) const override;

 private:
  // Sets p's base and the camera pose it implies: the one place the two
  // are kept in step.
  void SetBase(const Pose2d& base, Particle* p) const;

  Rigid3d base_from_cam_;
  OdometryNoise2d noise_;
};

// world_from_cam itself (Particle::base unused).
class SixDofStateModel : public StateModel {
 public:
  // `map_trajectory`: the poses random states take height and tilt from
  // when no reference is given (may be empty).
  SixDofStateModel(const OdometryNoise6d& noise,
                   std::vector<Rigid3d> map_trajectory)
      : noise_(noise), map_trajectory_(std::move(map_trajectory)) {}

  Particle FromPose(const Rigid3d& world_from_cam) const override;
  void Predict(const OdometryIncrement& odometry, Rng* rng,
               Particle* p) const override;
  // Throws StageError without a reference and a map trajectory.
  Particle Random(const SamplingArea& area,
                  const std::optional<Rigid3d>& reference,
                  Rng* rng) const override;
  std::vector<Particle> AroundPose(const Rigid3d& world_from_cam, int n,
                                   double spread_m, double spread_rad,
                                   Rng* rng) const override;
  KldBin Bin(const Particle& p, const KldOptions& options) const override;

 private:
  OdometryNoise6d noise_;
  std::vector<Rigid3d> map_trajectory_;
};

}  // namespace monomap
