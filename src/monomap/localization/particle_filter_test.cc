#include "monomap/localization/particle_filter.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "monomap/localization/state_model.h"

namespace monomap {
namespace {

double Sq(double x) { return x * x; }

TEST(OdometryMotion2d, MomentsMatchTheModel) {
  OdometryNoise2d noise;
  noise.alpha1 = 2e-3;
  noise.alpha2 = 1e-3;
  noise.alpha3 = 4e-3;
  noise.alpha4 = 2e-3;
  noise.floor_trans_m = 0.0;
  noise.floor_rot_rad = 0.0;
  const Pose2d start{1.0, 2.0, 0.3};
  const Pose2d odom_prev{0.0, 0.0, 0.0};
  const Pose2d odom_cur{0.5, 0.1, 0.2};
  OdometryNoise2d zero = noise;
  zero.alpha1 = zero.alpha2 = zero.alpha3 = zero.alpha4 = 0.0;
  Rng rng(3);
  const Pose2d exact =
      SampleOdometryMotion2d(start, odom_prev, odom_cur, zero, &rng);
  // The noiseless increment moves the start by the odometry's motion
  // expressed in the start frame.
  const double trans = std::hypot(0.5, 0.1);
  const double rot1 = std::atan2(0.1, 0.5);
  const double rot2 = 0.2 - rot1;
  EXPECT_NEAR(exact.x, 1.0 + trans * std::cos(0.3 + rot1), 1e-12);
  EXPECT_NEAR(exact.y, 2.0 + trans * std::sin(0.3 + rot1), 1e-12);
  EXPECT_NEAR(exact.yaw, 0.5, 1e-12);

  const int n = 40000;
  double sx = 0, sy = 0, syaw = 0, sxx = 0, syy = 0, syawyaw = 0;
  double st = 0, stt = 0;
  for (int i = 0; i < n; ++i) {
    const Pose2d p =
        SampleOdometryMotion2d(start, odom_prev, odom_cur, noise, &rng);
    const double t = std::hypot(p.x - start.x, p.y - start.y);
    const double dyaw = WrapAngle(p.yaw - exact.yaw);
    sx += p.x;
    sy += p.y;
    syaw += dyaw;
    sxx += p.x * p.x;
    syy += p.y * p.y;
    syawyaw += dyaw * dyaw;
    st += t;
    stt += t * t;
  }
  const double mx = sx / n, my = sy / n, myaw = syaw / n;
  const double sdx = std::sqrt(sxx / n - mx * mx);
  const double sdy = std::sqrt(syy / n - my * my);
  const double sdyaw = std::sqrt(syawyaw / n - myaw * myaw);
  EXPECT_NEAR(mx, exact.x, 3 * sdx / std::sqrt(n));
  EXPECT_NEAR(my, exact.y, 3 * sdy / std::sqrt(n));
  EXPECT_NEAR(myaw, 0.0, 3 * sdyaw / std::sqrt(n));

  const double var_trans = stt / n - Sq(st / n);
  const double expected_trans =
      noise.alpha3 * Sq(trans) + noise.alpha4 * (Sq(rot1) + Sq(rot2));
  EXPECT_NEAR(var_trans / expected_trans, 1.0, 0.1);
  EXPECT_NEAR(st / n, trans, 3 * std::sqrt(expected_trans / n));
  // yaw = yaw0 + rot1 + rot2 with independent noises.
  const double expected_yaw = noise.alpha1 * (Sq(rot1) + Sq(rot2)) +
                              2 * noise.alpha2 * Sq(trans);
  EXPECT_NEAR(Sq(sdyaw) / expected_yaw, 1.0, 0.1);
}

TEST(OdometryMotion2d, PureRotationKeepsPosition) {
  OdometryNoise2d noise;
  noise.floor_trans_m = 0.0;
  noise.floor_rot_rad = 0.0;
  Rng rng(5);
  for (int i = 0; i < 100; ++i) {
    const Pose2d p = SampleOdometryMotion2d({1, 1, 0}, {0, 0, 0}, {0, 0, 0.5},
                                            noise, &rng);
    // alpha4 rot^2 gives a small translation noise only.
    EXPECT_LT(std::hypot(p.x - 1, p.y - 1), 0.1);
    EXPECT_NEAR(p.yaw, 0.5, 0.25);
  }
}

TEST(OdometryMotion6d, MeanAndSpreadFollowTheIncrement) {
  OdometryNoise6d noise;
  const Rigid3d start(QuaternionFromRotationVector({0.1, -0.2, 0.3}),
                      {1, 2, 0.5});
  const Rigid3d inc(QuaternionFromRotationVector({0, 0.05, 0}),
                    {0.02, 0.0, 0.1});
  Rng rng(7);
  const int n = 20000;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Vector3d sum_sq = Eigen::Vector3d::Zero();
  Eigen::Vector3d rot_sum_sq = Eigen::Vector3d::Zero();
  const Rigid3d exact = start * inc;
  for (int i = 0; i < n; ++i) {
    const Rigid3d p = SampleOdometryMotion6d(start, inc, noise, &rng);
    // Noise in the (current) camera frame.
    const Rigid3d d = exact.Inverse() * p;
    sum += d.translation;
    sum_sq += d.translation.cwiseAbs2();
    rot_sum_sq += RotationVectorFromQuaternion(d.rotation).cwiseAbs2();
  }
  const double t = inc.translation.norm(), r = 0.05;
  const double st = noise.trans_per_m * t + noise.trans_per_rad * r +
                    noise.floor_trans_m;
  const double sr = noise.rot_per_rad * r + noise.rot_per_m * t +
                    noise.floor_rot_rad;
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(sum[k] / n, 0.0, 3 * st / std::sqrt(n));
    EXPECT_NEAR(std::sqrt(sum_sq[k] / n) / st, 1.0, 0.05);
    EXPECT_NEAR(std::sqrt(rot_sum_sq[k] / n) / sr, 1.0, 0.05);
  }
}

TEST(Resampling, LowVarianceIsUnbiased) {
  const std::vector<double> w = {0.05, 0.3, 0.01, 0.14, 0.2, 0.1, 0.2};
  const int n = 20;
  Rng rng(11);
  std::vector<double> mean(w.size(), 0.0);
  const int runs = 5000;
  for (int run = 0; run < runs; ++run) {
    const std::vector<int> idx = LowVarianceResample(w, n, &rng);
    ASSERT_EQ(idx.size(), static_cast<size_t>(n));
    std::vector<int> count(w.size(), 0);
    for (int i : idx) ++count[i];
    for (size_t i = 0; i < w.size(); ++i) {
      // Systematic resampling: floor or ceil of n w_i copies.
      EXPECT_GE(count[i], std::floor(n * w[i]) - 1e-9);
      EXPECT_LE(count[i], std::ceil(n * w[i]) + 1e-9);
      mean[i] += count[i];
    }
  }
  for (size_t i = 0; i < w.size(); ++i) {
    EXPECT_NEAR(mean[i] / runs, n * w[i], 0.03) << i;
  }
}

TEST(Resampling, EqualWeightsKeepEveryParticle) {
  Rng rng(1);
  const std::vector<double> w(50, 0.7);
  for (int run = 0; run < 20; ++run) {
    const std::vector<int> idx = LowVarianceResample(w, 50, &rng);
    for (int i = 0; i < 50; ++i) EXPECT_EQ(idx[i], i);
  }
  EXPECT_NEAR(EffectiveSampleSize(w), 50.0, 1e-9);
  std::vector<double> one_hot(50, 0.0);
  one_hot[3] = 1.0;
  EXPECT_NEAR(EffectiveSampleSize(one_hot), 1.0, 1e-12);
}

TEST(Kld, BoundMatchesFox2003) {
  EXPECT_NEAR(NormalQuantile(0.99), 2.326347874, 1e-6);
  EXPECT_NEAR(NormalQuantile(0.5), 0.0, 1e-9);
  const double z = 2.326347874;
  for (int k : {2, 10, 100, 1000}) {
    const double a = 2.0 / (9.0 * (k - 1));
    const double expected =
        (k - 1) / (2 * 0.05) * std::pow(1 - a + std::sqrt(a) * z, 3);
    EXPECT_NEAR(KldBound(k, 0.05, 0.01), expected, 1e-6 * expected) << k;
  }
  // The formula evaluated independently (Python): k = 2 -> 65.858,
  // k = 10 -> 216.966 (eps 0.05, delta 0.01).
  EXPECT_NEAR(KldBound(2, 0.05, 0.01), 65.858, 1e-3);
  EXPECT_NEAR(KldBound(10, 0.05, 0.01), 216.966, 1e-3);
  double prev = 0;
  for (int k = 2; k < 200; ++k) {
    const double b = KldBound(k, 0.05, 0.01);
    EXPECT_GT(b, prev);
    prev = b;
  }
  EXPECT_EQ(KldBound(1, 0.05, 0.01), 1.0);
}

TEST(Kld, ResampleCountGrowsWithSpread) {
  KldOptions o;
  o.min_particles = 50;
  o.max_particles = 5000;
  Rng rng(2);
  auto run = [&](double spread) {
    std::vector<Particle> ps(2000);
    std::normal_distribution<double> d(0.0, 1.0);
    // Centred in a bin, so that a tight cloud occupies one bin.
    const double yaw0 = -M_PI + o.bin_angle_rad * 36.5;
    for (Particle& p : ps) {
      p.base = {0.025 + spread * d(rng), 0.025 + spread * d(rng),
                yaw0 + 0.1 * spread * d(rng)};
    }
    const std::vector<double> w(ps.size(), 1.0);
    int bins = 0;
    const PlanarStateModel planar{Rigid3d(), OdometryNoise2d()};
    const std::vector<int> idx = KldResample(
        ps, w, o, [&](const Particle& p) { return planar.Bin(p, o); }, &rng,
        &bins);
    // The count is the bound of the bins seen (or the minimum).
    EXPECT_GE(static_cast<double>(idx.size()),
              std::min<double>(o.max_particles,
                               std::max<double>(o.min_particles,
                                                KldBound(bins, o.epsilon,
                                                         o.delta))) - 1e-9);
    return std::make_pair(static_cast<int>(idx.size()), bins);
  };
  const auto tight = run(0.001);  // one bin
  const auto medium = run(0.05);
  const auto wide = run(0.5);
  EXPECT_EQ(tight.first, o.min_particles);
  EXPECT_EQ(tight.second, 1);
  EXPECT_GT(medium.second, tight.second);
  EXPECT_GT(wide.second, medium.second);
  EXPECT_GT(medium.first, tight.first);
  EXPECT_GT(wide.first, medium.first);
}

TEST(Particles, MergeDuplicatesAddsWeights) {
  std::vector<Particle> ps(5);
  for (Particle& p : ps) p.log_weight = 0.0;
  ps[1].world_from_cam.translation = {0.002, 0, 0};
  ps[2].world_from_cam.rotation = QuaternionFromRotationVector({0, 0, 0.003});
  ps[3].world_from_cam.translation = {0.02, 0, 0};  // too far
  ps[4].world_from_cam.rotation = QuaternionFromRotationVector({0, 0.02, 0});
  const int removed = MergeDuplicateParticles(&ps, 0.005, 0.5 * M_PI / 180);
  EXPECT_EQ(removed, 2);
  ASSERT_EQ(ps.size(), 3u);
  const std::vector<double> w = NormalizedWeights(ps);
  EXPECT_NEAR(w[0], 0.6, 1e-9);
  EXPECT_NEAR(w[1], 0.2, 1e-9);
  EXPECT_NEAR(w[2], 0.2, 1e-9);
}

TEST(Particles, SpreadHeaviestSkipsTheCrowd) {
  // Six heavy particles within 5 cm (one mode), and lighter ones elsewhere:
  // 0.5 m away, at the crowd's position but turned 30 degrees, 1 m away.
  std::vector<Particle> ps(9);
  for (int i = 0; i < 6; ++i) {
    ps[i].world_from_cam.translation = {0.01 * i, 0, 0};
    ps[i].log_weight = -0.1 * i;
  }
  ps[6].world_from_cam.translation = {0.5, 0, 0};
  ps[6].log_weight = -2.0;
  ps[7].world_from_cam.translation = {0.01, 0, 0};
  ps[7].world_from_cam.rotation =
      QuaternionFromRotationVector({0, 0, 30 * M_PI / 180});
  ps[7].log_weight = -3.0;
  ps[8].world_from_cam.translation = {1.0, 0, 0};
  ps[8].log_weight = -4.0;
  const double ten_deg = 10 * M_PI / 180;
  EXPECT_EQ(SpreadHeaviest(ps, 3, 0.1, ten_deg),
            (std::vector<size_t>{0, 6, 7}));
  // Only four are apart: the crowd's next heaviest fill up.
  EXPECT_EQ(SpreadHeaviest(ps, 6, 0.1, ten_deg),
            (std::vector<size_t>{0, 6, 7, 8, 1, 2}));
  // No spread: the plain top k.
  EXPECT_EQ(SpreadHeaviest(ps, 3, 0.0, 0.0), (std::vector<size_t>{0, 1, 2}));
  EXPECT_EQ(SpreadHeaviest(ps, 20, 0.1, ten_deg).size(), 9u);
}

TEST(Particles, WeightedMeanPoseIgnoresQuaternionSign) {
  std::vector<Rigid3d> poses = {
      Rigid3d(QuaternionFromRotationVector({0, 0, 0.1}), {1, 0, 0}),
      Rigid3d(QuaternionFromRotationVector({0, 0, -0.1}), {3, 0, 0})};
  // The same rotation with the opposite quaternion sign.
  poses[1].rotation.coeffs() *= -1.0;
  const Rigid3d m = WeightedMeanPose(poses, {1.0, 1.0});
  EXPECT_NEAR(m.translation.x(), 2.0, 1e-12);
  EXPECT_LT(AngleBetween(m.rotation, Eigen::Quaterniond::Identity()), 1e-9);
  const Rigid3d m2 = WeightedMeanPose(poses, {3.0, 1.0});
  EXPECT_NEAR(m2.translation.x(), 1.5, 1e-12);
  EXPECT_NEAR(RotationVectorFromQuaternion(m2.rotation).z(), 0.05, 2e-3);
}

}  // namespace
}  // namespace monomap
