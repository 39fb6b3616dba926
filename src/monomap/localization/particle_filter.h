// Building blocks of a particle filter over camera poses: particles,
// odometry motion models (planar and 6-DoF), low-variance resampling, the
// effective sample size, KLD-sampling (Fox 2003) to adapt the particle
// count, merging of duplicates and a robust weighted mean pose. Nothing
// here knows about images; measurement_model.h weighs particles.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <random>
#include <vector>

#include <Eigen/Core>

#include "monomap/geometry/rigid3.h"
#include "monomap/geometry/pose2d.h"

namespace monomap {

using Rng = std::mt19937_64;

// One hypothesis. `world_from_cam` is always valid; with the planar state
// `base` is the state and world_from_cam = WorldFromCamOfBase(base, mount).
// Particles are made and moved by a StateModel (state_model.h), which keeps
// the two in step.
struct Particle {
  Rigid3d world_from_cam;
  Pose2d base;
  // Unnormalized log weight (log likelihoods add up between resamplings).
  double log_weight = 0.0;
};

// Wraps an angle to (-pi, pi].
double WrapAngle(double a);

// Noise of the planar odometry motion model (Thrun et al., Probabilistic
// Robotics, sample_motion_model_odometry). The alphas give variances:
// var(rot1) = a1 rot1^2 + a2 trans^2, var(trans) = a3 trans^2 +
// a4 (rot1^2 + rot2^2), var(rot2) = a1 rot2^2 + a2 trans^2.
struct OdometryNoise2d {
  // Rotation variance per squared rotation (rad^2/rad^2).
  double alpha1 = 0.01;
  // Rotation variance per squared translation (rad^2/m^2).
  double alpha2 = 0.01;
  // Translation variance per squared translation (m^2/m^2).
  double alpha3 = 0.01;
  // Translation variance per squared rotation (m^2/rad^2).
  double alpha4 = 0.001;
  // Standard deviations added even without motion (m, rad), so that a
  // standing robot's particles keep some diversity; 0 gives the textbook
  // model.
  double floor_trans_m = 0.002;
  double floor_rot_rad = 0.002;

  void Check() const;
};

// Samples the base pose after the odometry moved from odom_prev to
// odom_cur, starting at `pose`.
Pose2d SampleOdometryMotion2d(const Pose2d& pose, const Pose2d& odom_prev,
                              const Pose2d& odom_cur,
                              const OdometryNoise2d& noise, Rng* rng);

// Noise of the 6-DoF odometry model: the increment cam_prev_from_cam_cur
// is applied on the right (in the camera frame) followed by a random
// motion exp(w, v) whose per-axis standard deviations grow with the size
// of the increment.
struct OdometryNoise6d {
  // Translation std per metre travelled (m/m).
  double trans_per_m = 0.05;
  // Translation std per radian turned (m/rad).
  double trans_per_rad = 0.01;
  // Rotation std per radian turned (rad/rad).
  double rot_per_rad = 0.05;
  // Rotation std per metre travelled (rad/m).
  double rot_per_m = 0.02;
  // Standard deviations added even without motion (m, rad).
  double floor_trans_m = 0.002;
  double floor_rot_rad = 0.002;

  void Check() const;
};

Rigid3d SampleOdometryMotion6d(const Rigid3d& world_from_cam,
                               const Rigid3d& cam_prev_from_cam_cur,
                               const OdometryNoise6d& noise, Rng* rng);

// Normalized weights (sum 1) from log weights, computed stably.
std::vector<double> NormalizedWeights(const std::vector<Particle>& particles);

// 1 / sum w_i^2 of normalized weights.
double EffectiveSampleSize(const std::vector<double>& weights);

// Low-variance (systematic) resampling: `n` indices into `weights`
// (normalized or not), particle i drawn floor or ceil of n * w_i times.
std::vector<int> LowVarianceResample(const std::vector<double>& weights,
                                     int n, Rng* rng);

// Quantile z of the standard normal: P(Z <= z) = p, 0 < p < 1.
double NormalQuantile(double p);

// Fox 2003: number of samples so that, with probability 1 - delta, the KL
// divergence between the sample-based and the true posterior (both over k
// occupied bins) stays below epsilon:
//   n = (k-1)/(2 eps) * (1 - 2/(9(k-1)) + sqrt(2/(9(k-1))) z_{1-delta})^3.
// Returns 1 for k <= 1.
double KldBound(int k, double epsilon, double delta);

struct KldOptions {
  // Bin sizes of the histogram (x and y, z, angles); the state model
  // decides which coordinates it has (StateModel::Bin).
  double bin_xy_m = 0.05;
  double bin_z_m = 0.05;
  double bin_angle_rad = 0.0873;  // 5 degrees
  // Bound on the KL divergence (Fox 2003 epsilon).
  double epsilon = 0.05;
  // 1 - delta is the probability that the bound holds.
  double delta = 0.01;
  // Particle count limits.
  int min_particles = 100;
  int max_particles = 5000;

  void Check() const;
};

// A cell of the (x, y, z, roll, pitch, yaw) histogram of KLD-sampling
// (coordinates a state does not have are 0).
using KldBin = std::array<int64_t, 6>;
using KldBinFunction = std::function<KldBin(const Particle&)>;

// KLD resampling: draws a low-variance sample of max_particles, shuffles it
// and keeps the shortest prefix whose count reaches
// max(min_particles, KldBound(occupied bins)), bins given by `bin_of`.
// Returns indices into `weights`; `bins` (optional) receives the number of
// occupied bins.
std::vector<int> KldResample(const std::vector<Particle>& particles,
                             const std::vector<double>& weights,
                             const KldOptions& options,
                             const KldBinFunction& bin_of, Rng* rng,
                             int* bins = nullptr);

// Merges particles closer than max_translation_m and max_rotation_rad to
// an earlier (heavier) one into it, adding up their weights. Returns how
// many were removed.
int MergeDuplicateParticles(std::vector<Particle>* particles,
                            double max_translation_m,
                            double max_rotation_rad);

// Indices of up to k particles, heaviest first, each at least min_distance_m
// or min_angle_rad away from every one picked before it (a greedy
// non-maximum suppression over poses); if fewer than k are that far apart,
// the heaviest of the others fill up. With both limits 0: the k heaviest.
std::vector<size_t> SpreadHeaviest(const std::vector<Particle>& particles,
                                   size_t k, double min_distance_m,
                                   double min_angle_rad);

// Weighted mean of poses: translation averaged, rotation by the
// eigenvector of sum w q q^T (Markley et al. 2007), which is insensitive
// to the sign of q. Weights need not be normalized.
Rigid3d WeightedMeanPose(const std::vector<Rigid3d>& poses,
                         const std::vector<double>& weights);

// Weighted mean of the cluster around the heaviest particle: particles
// within radius_m and angle_rad of it. *cluster_weight (optional) gets the
// cluster's share of the total weight.
Rigid3d BestClusterMean(const std::vector<Particle>& particles,
                        const std::vector<double>& weights, double radius_m,
                        double angle_rad, double* cluster_weight = nullptr);

}  // namespace monomap
