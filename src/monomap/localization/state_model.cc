#include "monomap/localization/state_model.h"

#include <cmath>
#include <random>

#include "monomap/util/error.h"

namespace monomap {

namespace {

// Histogram coordinate of a value.
int64_t BinOf(double v, double size) {
  return static_cast<int64_t>(std::floor(v / size));
}

// A draw of `d`, or 0 when it has no spread.
double Draw(std::normal_distribution<double>& d, Rng* rng) {
  return d.stddev() > 0 ? d(*rng) : 0.0;
}

}  // namespace

void PlanarStateModel::SetBase(const Pose2d& base, Particle* p) const {
  p->base = base;
  p->world_from_cam = WorldFromCamOfBase(base, base_from_cam_);
}

Particle PlanarStateModel::FromPose(const Rigid3d& world_from_cam) const {
  Particle p;
  SetBase(BaseOfWorldFromCam(world_from_cam, base_from_cam_), &p);
  return p;
}

void PlanarStateModel::Predict(const OdometryIncrement& odometry, Rng* rng,
                               Particle* p) const {
  SetBase(SampleOdometryMotion2d(p->base, odometry.base_prev, odometry.base_cur,
                                 noise_, rng),
          p);
}

Particle PlanarStateModel::Random(const SamplingArea& area,
                                  const std::optional<Rigid3d>& /*reference*/,
                                  Rng* rng) const {
  std::uniform_real_distribution<double> ux(area.min.x(), area.max.x());
  std::uniform_real_distribution<double> uy(area.min.y(), area.max.y());
  std::uniform_real_distribution<double> uyaw(-M_PI, M_PI);
  Particle p;
  // A braced list: the draws happen in this order.
  SetBase(Pose2d{ux(*rng), uy(*rng), uyaw(*rng)}, &p);
  return p;
}

std::vector<Particle> PlanarStateModel::AroundPose(
    const Rigid3d& world_from_cam, int n, double spread_m, double spread_rad,
    Rng* rng) const {
  // One distribution for all draws: the sequence of draws is part of what
  // a seed reproduces.
  std::normal_distribution<double> dt(0.0, spread_m);
  std::normal_distribution<double> dr(0.0, spread_rad);
  const Pose2d b = BaseOfWorldFromCam(world_from_cam, base_from_cam_);
  std::vector<Particle> out(n);
  for (Particle& p : out) {
    SetBase(Pose2d{b.x + Draw(dt, rng), b.y + Draw(dt, rng),
                   WrapAngle(b.yaw + Draw(dr, rng))},
            &p);
  }
  return out;
}

KldBin PlanarStateModel::Bin(const Particle& p, const KldOptions& o) const {
  return {BinOf(p.base.x, o.bin_xy_m),
          BinOf(p.base.y, o.bin_xy_m),
          BinOf(WrapAngle(p.base.yaw) + M_PI, o.bin_angle_rad),
          0,
          0,
          0};
}

Particle SixDofStateModel::FromPose(const Rigid3d& world_from_cam) const {
  Particle p;
  p.world_from_cam = world_from_cam;
  return p;
}

void SixDofStateModel::Predict(const OdometryIncrement& odometry, Rng* rng,
                               Particle* p) const {
  p->world_from_cam = SampleOdometryMotion6d(
      p->world_from_cam, odometry.cam_prev_from_cam_cur, noise_, rng);
}

Particle SixDofStateModel::Random(const SamplingArea& area,
                                  const std::optional<Rigid3d>& reference,
                                  Rng* rng) const {
  std::uniform_real_distribution<double> ux(area.min.x(), area.max.x());
  std::uniform_real_distribution<double> uy(area.min.y(), area.max.y());
  std::uniform_real_distribution<double> uyaw(-M_PI, M_PI);
  Rigid3d ref = reference.value_or(Rigid3d());
  if (!reference) {
    if (map_trajectory_.empty()) {
      throw StageError(
          "6-DoF global init needs a reference pose or a map "
          "trajectory for the camera height and tilt");
    }
    std::uniform_int_distribution<size_t> pick(0, map_trajectory_.size() - 1);
    ref = map_trajectory_[pick(*rng)];
  }
  // Keep height, roll and pitch of the reference; draw x, y and yaw.
  const Eigen::Quaterniond q = YawRotation(uyaw(*rng)) * ref.rotation;
  Particle p;
  const double y = uy(*rng);  // y before x: see util/random.h
  p.world_from_cam =
      Rigid3d(q, Eigen::Vector3d(ux(*rng), y, ref.translation.z()));
  return p;
}

std::vector<Particle> SixDofStateModel::AroundPose(
    const Rigid3d& world_from_cam, int n, double spread_m, double spread_rad,
    Rng* rng) const {
  std::normal_distribution<double> dt(0.0, spread_m);
  std::normal_distribution<double> dr(0.0, spread_rad);
  std::vector<Particle> out(n);
  for (Particle& p : out) {
    Eigen::Vector3d v, w;
    for (int k = 0; k < 3; ++k) v[k] = Draw(dt, rng);
    for (int k = 0; k < 3; ++k) w[k] = Draw(dr, rng);
    p.world_from_cam =
        Rigid3d(QuaternionFromRotationVector(w) * world_from_cam.rotation,
                world_from_cam.translation + v);
  }
  return out;
}

KldBin SixDofStateModel::Bin(const Particle& p, const KldOptions& o) const {
  const Eigen::Vector3d& t = p.world_from_cam.translation;
  const Eigen::Vector3d w =
      RotationVectorFromQuaternion(p.world_from_cam.rotation);
  return {BinOf(t.x(), o.bin_xy_m),     BinOf(t.y(), o.bin_xy_m),
          BinOf(t.z(), o.bin_z_m),      BinOf(w[0], o.bin_angle_rad),
          BinOf(w[1], o.bin_angle_rad), BinOf(w[2], o.bin_angle_rad)};
}

}  // namespace monomap
