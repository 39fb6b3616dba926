#include "monomap/localization/particle_filter.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <unordered_set>

#include <Eigen/Eigenvalues>

#include "monomap/util/error.h"

namespace monomap {

namespace {

double Sq(double x) { return x * x; }

double Gaussian(double stddev, Rng* rng) {
  if (stddev <= 0.0) return 0.0;
  std::normal_distribution<double> d(0.0, stddev);
  return d(*rng);
}

}  // namespace

double WrapAngle(double a) {
  a = std::remainder(a, 2.0 * M_PI);
  if (a <= -M_PI) a += 2.0 * M_PI;
  return a;
}

void OdometryNoise2d::Check() const {
  CheckOption(alpha1 >= 0 && alpha2 >= 0 && alpha3 >= 0 && alpha4 >= 0,
              "odometry_noise2d.alpha", "must be >= 0");
  CheckOption(floor_trans_m >= 0, "odometry_noise2d.floor_trans_m",
              "must be >= 0");
  CheckOption(floor_rot_rad >= 0, "odometry_noise2d.floor_rot_rad",
              "must be >= 0");
}

Pose2d SampleOdometryMotion2d(const Pose2d& pose, const Pose2d& odom_prev,
                              const Pose2d& odom_cur,
                              const OdometryNoise2d& n, Rng* rng) {
  const double dx = odom_cur.x - odom_prev.x;
  const double dy = odom_cur.y - odom_prev.y;
  const double trans = std::hypot(dx, dy);
  // With (almost) no translation the heading of the motion is undefined:
  // put the whole rotation into rot2.
  const double rot1 =
      trans < 1e-6 ? 0.0 : WrapAngle(std::atan2(dy, dx) - odom_prev.yaw);
  const double rot2 = WrapAngle(odom_cur.yaw - odom_prev.yaw - rot1);
  const double var_rot1 = n.alpha1 * Sq(rot1) + n.alpha2 * Sq(trans);
  const double var_trans =
      n.alpha3 * Sq(trans) + n.alpha4 * (Sq(rot1) + Sq(rot2));
  const double var_rot2 = n.alpha1 * Sq(rot2) + n.alpha2 * Sq(trans);
  const double r1 = rot1 - Gaussian(std::sqrt(var_rot1), rng);
  const double t = trans - Gaussian(std::sqrt(var_trans), rng);
  const double r2 = rot2 - Gaussian(std::sqrt(var_rot2), rng);
  Pose2d out;
  out.x = pose.x + t * std::cos(pose.yaw + r1);
  out.y = pose.y + t * std::sin(pose.yaw + r1);
  out.yaw = pose.yaw + r1 + r2;
  // The floor noise is isotropic in the base frame.
  out.x += Gaussian(n.floor_trans_m, rng);
  out.y += Gaussian(n.floor_trans_m, rng);
  out.yaw = WrapAngle(out.yaw + Gaussian(n.floor_rot_rad, rng));
  return out;
}

void OdometryNoise6d::Check() const {
  CheckOption(trans_per_m >= 0, "odometry_noise6d.trans_per_m", "must be >= 0");
  CheckOption(trans_per_rad >= 0, "odometry_noise6d.trans_per_rad",
              "must be >= 0");
  CheckOption(rot_per_rad >= 0, "odometry_noise6d.rot_per_rad", "must be >= 0");
  CheckOption(rot_per_m >= 0, "odometry_noise6d.rot_per_m", "must be >= 0");
  CheckOption(floor_trans_m >= 0, "odometry_noise6d.floor_trans_m",
              "must be >= 0");
  CheckOption(floor_rot_rad >= 0, "odometry_noise6d.floor_rot_rad",
              "must be >= 0");
}

Rigid3d SampleOdometryMotion6d(const Rigid3d& world_from_cam,
                               const Rigid3d& cam_prev_from_cam_cur,
                               const OdometryNoise6d& n, Rng* rng) {
  const double trans = cam_prev_from_cam_cur.translation.norm();
  const double rot = RotationVectorFromQuaternion(
                         cam_prev_from_cam_cur.rotation).norm();
  const double st = n.trans_per_m * trans + n.trans_per_rad * rot +
                    n.floor_trans_m;
  const double sr = n.rot_per_rad * rot + n.rot_per_m * trans +
                    n.floor_rot_rad;
  Eigen::Vector3d v, w;
  for (int i = 0; i < 3; ++i) v[i] = Gaussian(st, rng);
  for (int i = 0; i < 3; ++i) w[i] = Gaussian(sr, rng);
  const Rigid3d noise(QuaternionFromRotationVector(w), v);
  return world_from_cam * cam_prev_from_cam_cur * noise;
}

std::vector<double> NormalizedWeights(const std::vector<Particle>& particles) {
  std::vector<double> w(particles.size(), 0.0);
  if (particles.empty()) return w;
  double max_log = -std::numeric_limits<double>::infinity();
  for (const Particle& p : particles) max_log = std::max(max_log, p.log_weight);
  double sum = 0.0;
  for (size_t i = 0; i < particles.size(); ++i) {
    w[i] = std::isfinite(max_log) ? std::exp(particles[i].log_weight - max_log)
                                  : 1.0;
    sum += w[i];
  }
  for (double& x : w) x /= sum;
  return w;
}

double EffectiveSampleSize(const std::vector<double>& weights) {
  double sum = 0.0, sum_sq = 0.0;
  for (double w : weights) {
    sum += w;
    sum_sq += w * w;
  }
  return sum_sq > 0.0 ? sum * sum / sum_sq : 0.0;
}

std::vector<int> LowVarianceResample(const std::vector<double>& weights,
                                     int n, Rng* rng) {
  std::vector<int> out;
  if (weights.empty() || n <= 0) return out;
  const double total = std::accumulate(weights.begin(), weights.end(), 0.0);
  if (!(total > 0.0)) throw StageError("resampling: weights sum to zero");
  out.reserve(n);
  const double step = total / n;
  std::uniform_real_distribution<double> u(0.0, step);
  const double r = u(*rng);
  double c = weights[0];
  size_t i = 0;
  for (int m = 0; m < n; ++m) {
    const double target = r + m * step;
    while (target > c && i + 1 < weights.size()) c += weights[++i];
    out.push_back(static_cast<int>(i));
  }
  return out;
}

double NormalQuantile(double p) {
  if (!(p > 0.0 && p < 1.0)) throw OptionsError("NormalQuantile: p in (0, 1)");
  // Bisection on the CDF 0.5 erfc(-z / sqrt 2): plenty fast for options.
  double lo = -40.0, hi = 40.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (0.5 * std::erfc(-mid / std::sqrt(2.0)) < p) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  return 0.5 * (lo + hi);
}

double KldBound(int k, double epsilon, double delta) {
  if (k <= 1) return 1.0;
  const double z = NormalQuantile(1.0 - delta);
  const double a = 2.0 / (9.0 * (k - 1));
  const double b = 1.0 - a + std::sqrt(a) * z;
  return (k - 1) / (2.0 * epsilon) * b * b * b;
}

void KldOptions::Check() const {
  CheckOption(bin_xy_m > 0, "kld.bin_xy_m", "must be > 0");
  CheckOption(bin_z_m > 0, "kld.bin_z_m", "must be > 0");
  CheckOption(bin_angle_rad > 0, "kld.bin_angle_rad", "must be > 0");
  CheckOption(epsilon > 0, "kld.epsilon", "must be > 0");
  CheckOption(delta > 0 && delta < 1, "kld.delta", "must be in (0, 1)");
  CheckOption(min_particles >= 1, "kld.min_particles", "must be >= 1");
  CheckOption(max_particles >= min_particles, "kld.max_particles",
              "must be >= min_particles");
}

namespace {

// Hash of a histogram bin.
uint64_t BinHash(const KldBin& c) {
  uint64_t h = 1469598103934665603ull;
  for (int64_t v : c) {
    h ^= static_cast<uint64_t>(v) + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
  }
  return h;
}

}  // namespace

std::vector<int> KldResample(const std::vector<Particle>& particles,
                             const std::vector<double>& weights,
                             const KldOptions& o,
                             const KldBinFunction& bin_of, Rng* rng,
                             int* bins) {
  std::vector<int> all = LowVarianceResample(weights, o.max_particles, rng);
  // A random prefix of a systematic sample is a sample without replacement
  // from it: unbiased, and with less variance than multinomial draws.
  std::shuffle(all.begin(), all.end(), *rng);
  std::unordered_set<uint64_t> occupied;
  std::vector<int> out;
  out.reserve(all.size());
  // The bound only changes when a new bin is hit; cache it.
  double needed = o.min_particles;
  for (int idx : all) {
    out.push_back(idx);
    if (occupied.insert(BinHash(bin_of(particles[idx]))).second) {
      needed = std::max<double>(
          o.min_particles,
          KldBound(static_cast<int>(occupied.size()), o.epsilon, o.delta));
    }
    if (static_cast<double>(out.size()) >= needed) break;
  }
  if (bins) *bins = static_cast<int>(occupied.size());
  return out;
}

std::vector<size_t> SpreadHeaviest(const std::vector<Particle>& particles,
                                   size_t k, double min_distance_m,
                                   double min_angle_rad) {
  std::vector<size_t> order(particles.size());
  std::iota(order.begin(), order.end(), 0);
  // Stable, so that equal weights keep the particle order (determinism).
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return particles[a].log_weight > particles[b].log_weight;
  });
  k = std::min(k, order.size());
  if (min_distance_m <= 0.0 && min_angle_rad <= 0.0) {
    order.resize(k);
    return order;
  }
  std::vector<size_t> picked;
  std::vector<char> taken(order.size(), 0);
  picked.reserve(k);
  for (size_t r = 0; r < order.size() && picked.size() < k; ++r) {
    const Rigid3d& p = particles[order[r]].world_from_cam;
    bool apart = true;
    for (size_t q : picked) {
      const Rigid3d& o = particles[q].world_from_cam;
      if ((p.translation - o.translation).norm() < min_distance_m &&
          AngleBetween(p.rotation, o.rotation) < min_angle_rad) {
        apart = false;
        break;
      }
    }
    if (apart) {
      picked.push_back(order[r]);
      taken[r] = 1;
    }
  }
  for (size_t r = 0; r < order.size() && picked.size() < k; ++r) {
    if (!taken[r]) picked.push_back(order[r]);
  }
  return picked;
}

int MergeDuplicateParticles(std::vector<Particle>* particles,
                            double max_translation_m,
                            double max_rotation_rad) {
  std::vector<Particle>& ps = *particles;
  const size_t n = ps.size();
  if (n < 2) return 0;
  // Heaviest first, so that duplicates merge into the best one; then a
  // sweep along x bounds the pairs compared.
  std::vector<size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::vector<size_t> by_x = order;
  std::sort(by_x.begin(), by_x.end(), [&](size_t a, size_t b) {
    return ps[a].world_from_cam.translation.x() <
           ps[b].world_from_cam.translation.x();
  });
  std::vector<size_t> pos_in_x(n);
  for (size_t i = 0; i < n; ++i) pos_in_x[by_x[i]] = i;
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return ps[a].log_weight > ps[b].log_weight;
  });
  std::vector<int> merged_into(n, -1);
  std::vector<double> extra(n, 0.0);  // weights (relative) merged in
  const double max_log =
      ps[order[0]].log_weight;  // reference for relative weights
  int removed = 0;
  for (size_t i : order) {
    if (merged_into[i] >= 0) continue;
    const Rigid3d& pi = ps[i].world_from_cam;
    auto visit = [&](size_t j) {
      if (j == i || merged_into[j] >= 0) return;
      const Rigid3d& pj = ps[j].world_from_cam;
      if ((pi.translation - pj.translation).norm() > max_translation_m) return;
      if (AngleBetween(pi.rotation, pj.rotation) > max_rotation_rad) return;
      merged_into[j] = static_cast<int>(i);
      extra[i] += std::exp(ps[j].log_weight - max_log);
      ++removed;
    };
    const double x = pi.translation.x();
    for (size_t k = pos_in_x[i] + 1; k < n; ++k) {
      if (ps[by_x[k]].world_from_cam.translation.x() - x > max_translation_m)
        break;
      visit(by_x[k]);
    }
    for (size_t k = pos_in_x[i]; k-- > 0;) {
      if (x - ps[by_x[k]].world_from_cam.translation.x() > max_translation_m)
        break;
      visit(by_x[k]);
    }
  }
  if (removed == 0) return 0;
  std::vector<Particle> kept;
  kept.reserve(n - removed);
  for (size_t i = 0; i < n; ++i) {
    if (merged_into[i] >= 0) continue;
    Particle p = ps[i];
    if (extra[i] > 0.0) {
      p.log_weight = max_log + std::log(std::exp(p.log_weight - max_log) +
                                        extra[i]);
    }
    kept.push_back(p);
  }
  ps = std::move(kept);
  return removed;
}

Rigid3d WeightedMeanPose(const std::vector<Rigid3d>& poses,
                         const std::vector<double>& weights) {
  if (poses.empty()) throw StageError("WeightedMeanPose: no poses");
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
  double sum = 0.0;
  for (size_t i = 0; i < poses.size(); ++i) {
    const double w = weights[i];
    t += w * poses[i].translation;
    const Eigen::Vector4d q = poses[i].rotation.coeffs();
    m += w * q * q.transpose();
    sum += w;
  }
  if (!(sum > 0.0)) throw StageError("WeightedMeanPose: weights sum to zero");
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> es(m);
  const Eigen::Vector4d q = es.eigenvectors().col(3);  // largest eigenvalue
  return Rigid3d(Eigen::Quaterniond(q[3], q[0], q[1], q[2]), t / sum);
}

Rigid3d BestClusterMean(const std::vector<Particle>& particles,
                        const std::vector<double>& weights, double radius_m,
                        double angle_rad, double* cluster_weight) {
  if (particles.empty()) throw StageError("BestClusterMean: no particles");
  const size_t best = static_cast<size_t>(
      std::max_element(weights.begin(), weights.end()) - weights.begin());
  const Rigid3d& c = particles[best].world_from_cam;
  std::vector<Rigid3d> poses;
  std::vector<double> w;
  double total = 0.0, in = 0.0;
  for (size_t i = 0; i < particles.size(); ++i) {
    total += weights[i];
    const Rigid3d& p = particles[i].world_from_cam;
    if ((p.translation - c.translation).norm() > radius_m) continue;
    if (AngleBetween(p.rotation, c.rotation) > angle_rad) continue;
    poses.push_back(p);
    w.push_back(weights[i]);
    in += weights[i];
  }
  if (cluster_weight) *cluster_weight = total > 0 ? in / total : 0.0;
  return WeightedMeanPose(poses, w);
}

}  // namespace monomap
