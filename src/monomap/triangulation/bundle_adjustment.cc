#include "monomap/triangulation/bundle_adjustment.h"

#include <ceres/ceres.h>
#include <ceres/manifold.h>
#include <ceres/product_manifold.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <iostream>
#include <map>
#include <memory>
#include <unordered_map>

#include "monomap/geometry/triangulation.h"
#include "monomap/triangulation/projection.h"
#include "monomap/triangulation/triangulator.h"
#include "monomap/util/angles.h"
#include "monomap/util/error.h"
#include "monomap/util/progress.h"
#include "monomap/util/stats.h"

namespace monomap {
namespace {

// Pose parameters of one frame, one parameter block: cam_from_world as an
// Eigen quaternion (x, y, z, w memory layout, for
// ceres::EigenQuaternionManifold) followed by the translation. One block per
// pose (rather than rotation and translation apart) halves the number of
// camera blocks the Schur complement has to combine.
struct PoseParams {
  double v[7];
};
using PoseManifold = ceres::ProductManifold<ceres::EigenQuaternionManifold,
                                            ceres::EuclideanManifold<3>>;

PoseParams ToParams(const Rigid3d& cam_from_world) {
  PoseParams p;
  const Eigen::Quaterniond q = cam_from_world.rotation.normalized();
  std::copy(q.coeffs().data(), q.coeffs().data() + 4, p.v);
  std::copy(cam_from_world.translation.data(),
            cam_from_world.translation.data() + 3, p.v + 4);
  return p;
}

Rigid3d FromParams(const PoseParams& p) {
  return Rigid3d(Eigen::Quaterniond(p.v[3], p.v[0], p.v[1], p.v[2]),
                 Eigen::Vector3d(p.v[4], p.v[5], p.v[6]));
}

// Reprojection error (raw pixels) of a world point in a camera.
struct ReprojectionCost {
  ReprojectionCost(const internal::Intrinsics& intrinsics,
                   const Eigen::Vector2d& observed)
      : intrinsics(intrinsics), observed(observed) {}

  // With the camera's fixed distortion.
  template <typename T>
  bool operator()(const T* pose, const T* x, T* residual) const {
    return Residual(pose, x, intrinsics.v + 4, residual);
  }
  // With the distortion (k1, k2, p1, p2, k3) as a parameter block.
  template <typename T>
  bool operator()(const T* pose, const T* x, const T* distortion,
                  T* residual) const {
    return Residual(pose, x, distortion, residual);
  }

  // x_in_world -> *x_in_cam; false if the point is (nearly) on or behind
  // the image plane: it has no projection, the step is rejected.
  template <typename T>
  static bool ToCamera(const T* pose, const T* x,
                       Eigen::Matrix<T, 3, 1>* x_in_cam) {
    const Eigen::Map<const Eigen::Quaternion<T>> rotation(pose);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> translation(pose + 4);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> x_in_world(x);
    *x_in_cam = rotation * x_in_world + translation;
    return x_in_cam->z() > T(1e-6);
  }

  template <typename T, typename D>
  bool Residual(const T* pose, const T* x, const D* distortion,
                T* residual) const {
    Eigen::Matrix<T, 3, 1> x_in_cam;
    if (!ToCamera(pose, x, &x_in_cam)) return false;
    T px[2];
    internal::ProjectWithDistortion(intrinsics, distortion, x_in_cam.data(),
                                    px);
    residual[0] = px[0] - observed.x();
    residual[1] = px[1] - observed.y();
    return true;
  }

  static ceres::CostFunction* Create(const internal::Intrinsics& intrinsics,
                                     const Eigen::Vector2d& observed) {
    return new ceres::AutoDiffCostFunction<ReprojectionCost, 2, 7, 3>(
        new ReprojectionCost(intrinsics, observed));
  }
  static ceres::CostFunction* CreateWithDistortion(
      const internal::Intrinsics& intrinsics, const Eigen::Vector2d& observed) {
    return new ceres::AutoDiffCostFunction<ReprojectionCost, 2, 7, 3, 5>(
        new ReprojectionCost(intrinsics, observed));
  }

  internal::Intrinsics intrinsics;
  Eigen::Vector2d observed;
};

// Reprojection error (raw pixels) with the lens block (fx, fy, cx, cy, k1,
// k2) as a parameter (intrinsics_refinement.h).
struct LensReprojectionCost {
  template <typename T>
  bool operator()(const T* pose, const T* x, const T* lens, T* residual) const {
    Eigen::Matrix<T, 3, 1> x_in_cam;
    if (!ReprojectionCost::ToCamera(pose, x, &x_in_cam)) return false;
    T px[2];
    internal::ProjectWithLens(constants, lens, x_in_cam.data(), px);
    residual[0] = px[0] - observed.x();
    residual[1] = px[1] - observed.y();
    return true;
  }
  internal::LensConstants constants;
  Eigen::Vector2d observed;
};

// Prior on the relative motion cam_i_from_cam_j between two frames, from
// the odometry. Residual: rotation vector (small-angle, 2 vec(dq)) of
// measured^-1 * estimated over sigma_rot, translation difference (in cam_i)
// over sigma_t.
struct RelativePoseCost {
  RelativePoseCost(const Rigid3d& measured_i_from_j, double sigma_t,
                   double sigma_rot)
      : q_measured_inv(measured_i_from_j.rotation.conjugate()),
        t_measured(measured_i_from_j.translation),
        inv_sigma_t(1.0 / sigma_t),
        inv_sigma_rot(1.0 / sigma_rot) {}

  template <typename T>
  bool operator()(const T* pose_i, const T* pose_j, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q_i(pose_i), q_j(pose_j);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_i(pose_i + 4),
        t_j(pose_j + 4);
    // cam_i_from_cam_j = cam_i_from_world * (cam_j_from_world)^-1.
    const Eigen::Quaternion<T> q_ij = q_i * q_j.conjugate();
    const Eigen::Matrix<T, 3, 1> t_ij = t_i - q_ij * t_j;
    const Eigen::Quaternion<T> dq = q_measured_inv.cast<T>() * q_ij;
    // Sign of w chosen so the error is the short way round.
    const T sign = dq.w() < T(0) ? T(-1) : T(1);
    for (int k = 0; k < 3; ++k) {
      residual[k] = T(2.0 * inv_sigma_rot) * sign * dq.vec()[k];
      residual[3 + k] = T(inv_sigma_t) * (t_ij[k] - T(t_measured[k]));
    }
    return true;
  }

  Eigen::Quaterniond q_measured_inv;
  Eigen::Vector3d t_measured;
  double inv_sigma_t;
  double inv_sigma_rot;
};

// Absolute prior on a pose (used for the gauge when the first pose is not
// held fixed).
struct AbsolutePoseCost {
  AbsolutePoseCost(const Rigid3d& cam_from_world, double sigma_t,
                   double sigma_rot)
      : q_inv(cam_from_world.rotation.conjugate()),
        t(cam_from_world.translation),
        inv_sigma_t(1.0 / sigma_t),
        inv_sigma_rot(1.0 / sigma_rot) {}

  template <typename T>
  bool operator()(const T* pose, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> rotation(pose);
    const T* tr = pose + 4;
    const Eigen::Quaternion<T> dq = q_inv.cast<T>() * rotation;
    const T sign = dq.w() < T(0) ? T(-1) : T(1);
    for (int k = 0; k < 3; ++k) {
      residual[k] = T(2.0 * inv_sigma_rot) * sign * dq.vec()[k];
      residual[3 + k] = T(inv_sigma_t) * (tr[k] - T(t[k]));
    }
    return true;
  }

  Eigen::Quaterniond q_inv;
  Eigen::Vector3d t;
  double inv_sigma_t;
  double inv_sigma_rot;
};

// Prior that a wheeled base stays level and at its height: residuals are
// the horizontal components of the world's up axis in the base frame
// (roll and pitch, small-angle) over sigma_tilt and the base's height
// difference over sigma_height, against the values of the odometry pose.
struct PlanarBaseCost {
  PlanarBaseCost(const Rigid3d& base_from_cam,
                 const Rigid3d& odometry_world_from_cam, double sigma_tilt_rad,
                 double sigma_height_m)
      : q_base_from_cam(base_from_cam.rotation),
        t_base_from_cam(base_from_cam.translation),
        inv_sigma_tilt(1.0 / sigma_tilt_rad),
        inv_sigma_height(1.0 / sigma_height_m) {
    const Rigid3d world_from_base =
        odometry_world_from_cam * base_from_cam.Inverse();
    up_in_base =
        world_from_base.rotation.conjugate() * Eigen::Vector3d::UnitZ();
    height = world_from_base.translation.z();
  }

  template <typename T>
  bool operator()(const T* pose, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q_cam_from_world(pose);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_cam_from_world(pose + 4);
    const Eigen::Quaternion<T> q_base_from_world =
        q_base_from_cam.cast<T>() * q_cam_from_world;
    const Eigen::Matrix<T, 3, 1> t_base_from_world =
        q_base_from_cam.cast<T>() * t_cam_from_world +
        t_base_from_cam.cast<T>();
    const Eigen::Matrix<T, 3, 1> up =
        q_base_from_world * Eigen::Matrix<T, 3, 1>::UnitZ();
    // The base's origin in the world: -R^T t.
    const Eigen::Matrix<T, 3, 1> base_in_world =
        -(q_base_from_world.conjugate() * t_base_from_world);
    residual[0] = T(inv_sigma_tilt) * (up.x() - T(up_in_base.x()));
    residual[1] = T(inv_sigma_tilt) * (up.y() - T(up_in_base.y()));
    residual[2] = T(inv_sigma_height) * (base_in_world.z() - T(height));
    return true;
  }

  Eigen::Quaterniond q_base_from_cam;
  Eigen::Vector3d t_base_from_cam;
  Eigen::Vector3d up_in_base;
  double height = 0.0;
  double inv_sigma_tilt;
  double inv_sigma_height;
};

// Reprojection errors (raw px) of every observation of the given points;
// an observation behind its camera counts as a large error.
std::vector<double> ReprojectionErrors(
    const Camera& camera, const std::vector<Rigid3d>& cams_from_world,
    const std::vector<const Track*>& tracks,
    const std::vector<Eigen::Vector3d>& points) {
  std::vector<double> errors;
  for (size_t i = 0; i < tracks.size(); ++i) {
    for (const Observation& obs : tracks[i]->observations) {
      const Eigen::Vector3d xc = cams_from_world[obs.frame] * points[i];
      errors.push_back(xc.z() > 0 ? (camera.ImageFromCam(xc) - obs.px).norm()
                                  : 1e6);
    }
  }
  return errors;
}

void RmsAndMedian(std::vector<double> errors, double* rms, double* median) {
  *rms = 0.0;
  *median = 0.0;
  if (errors.empty()) return;
  double sum = 0.0;
  for (double e : errors) sum += e * e;
  *rms = std::sqrt(sum / errors.size());
  *median = UpperMedian(std::move(errors));
}

// Which landmarks enter the joint adjustment: all if max_points is 0 or not
// exceeded; otherwise the longest tracks (best constrained, linking the most
// poses), taken round-robin over the frames of their middle observation so
// every part of the trajectory keeps points. Deterministic.
std::vector<char> SelectJointPoints(const std::vector<const Track*>& tracks,
                                    int max_points) {
  const size_t n = tracks.size();
  if (max_points <= 0 || n <= static_cast<size_t>(max_points)) {
    return std::vector<char>(n, 1);
  }
  std::vector<char> joint(n, 0);
  std::map<int, std::vector<size_t>> by_frame;
  for (size_t i = 0; i < n; ++i) {
    const auto& obs = tracks[i]->observations;
    if (obs.empty()) continue;
    by_frame[obs[obs.size() / 2].frame].push_back(i);
  }
  for (auto& [frame, indices] : by_frame) {
    std::stable_sort(indices.begin(), indices.end(), [&](size_t a, size_t b) {
      return tracks[a]->observations.size() > tracks[b]->observations.size();
    });
  }
  int taken = 0;
  for (size_t round = 0; taken < max_points; ++round) {
    bool any = false;
    for (const auto& [frame, indices] : by_frame) {
      if (round >= indices.size()) continue;
      any = true;
      joint[indices[round]] = 1;
      if (++taken == max_points) break;
    }
    if (!any) break;
  }
  return joint;
}

// The landmarks' tracks, matched by id. Throws InputError if a landmark
// has no track or a track refers to a frame without pose.
std::vector<const Track*> MatchLandmarkTracks(
    const std::vector<Track>& tracks, const std::vector<Landmark>& landmarks,
    int num_frames) {
  std::unordered_map<FeatureId, const Track*> track_by_id;
  track_by_id.reserve(tracks.size());
  for (const Track& track : tracks) track_by_id.emplace(track.id, &track);
  std::vector<const Track*> landmark_tracks;
  landmark_tracks.reserve(landmarks.size());
  for (const Landmark& l : landmarks) {
    const auto it = track_by_id.find(l.id);
    if (it == track_by_id.end()) {
      throw InputError("bundle adjustment: landmark " + std::to_string(l.id) +
                       " has no track");
    }
    for (const Observation& obs : it->second->observations) {
      if (obs.frame < 0 || obs.frame >= num_frames) {
        throw InputError("bundle adjustment: track " + std::to_string(l.id) +
                         " observed in frame " + std::to_string(obs.frame) +
                         " which has no pose (" + std::to_string(num_frames) +
                         " poses)");
      }
    }
    landmark_tracks.push_back(it->second);
  }
  return landmark_tracks;
}

ceres::Problem::Options FastRemoval() {
  ceres::Problem::Options options;
  // Outlier observations and points leave the problem one by one.
  options.enable_fast_removal = true;
  return options;
}

// One adjustment, in the steps of a classic bundle adjuster: SetUpProblem
// (reprojection residuals of the joint landmarks, AddLandmarkToProblem),
// AddOdometryPriors, AddPlanarBasePriors, ParameterizePoses (manifolds,
// gauge), SetUpSolverOptions, Solve (and, after RemoveOutlierObservations,
// Solve again); then the poses are written back, the other
// landmarks refined alone and the landmarks updated. The order in which
// blocks enter the problem is fixed: results are reproducible bit for bit.
class BundleAdjuster {
 public:
  BundleAdjuster(const Camera& camera, const BundleAdjustmentOptions& options,
                 std::vector<const Track*> landmark_tracks,
                 const std::vector<Rigid3d>& world_from_cam,
                 const std::vector<Landmark>& landmarks,
                 BundleAdjustmentReport* report);
  ~BundleAdjuster() {
    if (!loss_owned_by_problem_) delete loss_;
  }
  BundleAdjuster(const BundleAdjuster&) = delete;
  BundleAdjuster& operator=(const BundleAdjuster&) = delete;

  // Adds the reprojection residuals; false if there are none (every joint
  // landmark behind a camera).
  bool SetUpProblem();
  void AddOdometryPriors();
  // After AddOdometryPriors (every adjusted pose is in the problem).
  void AddPlanarBasePriors();
  void ParameterizePoses();
  ceres::Solver::Options SetUpSolverOptions();
  // Throws StageError if Ceres fails.
  void Solve(const ceres::Solver::Options& solver_options);
  // Takes the observations whose reprojection error exceeds threshold_px
  // out of the problem (and the landmarks left with fewer than two);
  // returns how many observations.
  int RemoveOutlierObservations(double threshold_px);
  void WriteBackPoses(std::vector<Rigid3d>* world_from_cam);
  void RefineOtherLandmarks();
  void UpdateLandmarks(std::vector<Landmark>* landmarks);
  // Lens self-calibration: before SetUpProblem, the groups (focal,
  // principal point, radial) the adjustment refines (none: lens fixed).
  void SetFreeLensGroups(const std::array<bool, kNumLensGroups>& groups);
  // After Solve: marginal standard deviations of the lens block (0 for
  // fixed parameters); false if Ceres cannot compute the covariance.
  bool LensStandardDeviations(std::array<double, kLensSize>* stds);
  const std::array<double, kLensSize>& lens() const { return lens_; }

 private:
  bool LensFree() const { return AnyLensGroup(free_groups_); }
  // Prior and manifold (fixed groups constant) of the lens block.
  void ParameterizeLens();
  internal::LensConstants LensConstantsOf() const {
    return {camera_.model == LensModel::kEquidistant, camera_.distortion,
            ThirdRadialIndex(camera_.model), options_.intrinsics.shared_focal,
            camera_.fy / camera_.fx};
  }
  void AddLandmarkToProblem(size_t i);
  // Odometry prior on the relative pose of poses i and j.
  void AddOdometryPrior(int i, int j, double translation_fraction,
                        double rotation_floor_deg, double rotation_deg_per_m);

  const Camera& camera_;
  const internal::Intrinsics intrinsics_;
  const BundleAdjustmentOptions& options_;
  const std::vector<const Track*> landmark_tracks_;
  const std::vector<Rigid3d> odometry_;  // world_from_cam on input
  const int num_frames_;
  BundleAdjustmentReport& report_;
  // Parameter blocks: one pose per frame, one point per landmark, and the
  // distortion (k1, k2, p1, p2, k3; a block only with refine_distortion).
  std::vector<PoseParams> poses_;
  std::vector<Eigen::Vector3d> points_;
  std::array<double, 5> distortion_;
  // Lens block (fx, fy, cx, cy, k1, k2, k3) with self-calibration.
  std::array<double, kLensSize> lens_;
  std::array<bool, kNumLensGroups> free_groups_{};
  std::vector<Rigid3d> cams_from_world_;
  std::vector<char> joint_;  // landmarks in the joint problem
  // Reprojection residual blocks with their landmark index.
  std::vector<std::pair<ceres::ResidualBlockId, size_t>> reprojection_blocks_;
  // Frames adjusted (first_ .. last_); frames outside follow by odometry.
  int first_ = 0, last_ = 0;
  Camera adjusted_camera_;  // with the refined distortion
  ceres::Problem problem_{FastRemoval()};
  ceres::LossFunction* loss_ = nullptr;
  bool loss_owned_by_problem_ = false;
  int64_t sum_squared_track_length_ = 0;
};

BundleAdjuster::BundleAdjuster(const Camera& camera,
                               const BundleAdjustmentOptions& options,
                               std::vector<const Track*> landmark_tracks,
                               const std::vector<Rigid3d>& world_from_cam,
                               const std::vector<Landmark>& landmarks,
                               BundleAdjustmentReport* report)
    : camera_(camera),
      intrinsics_(camera),
      options_(options),
      landmark_tracks_(std::move(landmark_tracks)),
      odometry_(world_from_cam),
      num_frames_(static_cast<int>(world_from_cam.size())),
      report_(*report),
      poses_(num_frames_),
      points_(landmarks.size()),
      distortion_(camera.distortion),
      lens_(LensParameters(camera)),
      cams_from_world_(num_frames_),
      adjusted_camera_(camera) {
  for (int i = 0; i < num_frames_; ++i) {
    cams_from_world_[i] = odometry_[i].Inverse();
    poses_[i] = ToParams(cams_from_world_[i]);
  }
  for (size_t i = 0; i < landmarks.size(); ++i) {
    points_[i] = landmarks[i].x_in_world;
  }
  RmsAndMedian(
      ReprojectionErrors(camera_, cams_from_world_, landmark_tracks_, points_),
      &report_.initial_rms_error_px, &report_.initial_median_error_px);
}

bool BundleAdjuster::SetUpProblem() {
  if (options_.loss == "huber") {
    loss_ = new ceres::HuberLoss(options_.loss_scale_px);
  } else if (options_.loss == "cauchy") {
    loss_ = new ceres::CauchyLoss(options_.loss_scale_px);
  }
  joint_ = SelectJointPoints(landmark_tracks_, options_.max_points);
  for (size_t i = 0; i < points_.size(); ++i) {
    if (joint_[i]) AddLandmarkToProblem(i);
  }
  loss_owned_by_problem_ = report_.num_residuals > 0;
  if (report_.num_residuals == 0) return false;
  // Every frame between the first and last observed one takes part, tied by
  // the odometry priors; frames outside are left as they are.
  std::vector<bool> observed(num_frames_, false);
  for (int i = 0; i < num_frames_; ++i) {
    observed[i] = problem_.HasParameterBlock(poses_[i].v);
  }
  first_ = 0;
  last_ = num_frames_ - 1;
  while (first_ < num_frames_ && !observed[first_]) ++first_;
  while (last_ > first_ && !observed[last_]) --last_;
  // With the first pose as gauge, the chain must start there.
  if (options_.fix_first_pose) first_ = 0;
  return true;
}

void BundleAdjuster::AddLandmarkToProblem(size_t i) {
  const std::vector<Observation>& observations =
      landmark_tracks_[i]->observations;
  // A point behind one of its cameras has no valid residual (Ceres would
  // fail at the first evaluation): leave it out; it is dropped later.
  bool in_front = points_[i].allFinite();
  for (const Observation& obs : observations) {
    in_front = in_front &&
               DepthInCamera(cams_from_world_[obs.frame], points_[i]) > 1e-6;
  }
  if (!in_front) return;
  const int64_t k = static_cast<int64_t>(observations.size());
  sum_squared_track_length_ += k * k;
  for (const Observation& obs : observations) {
    PoseParams& p = poses_[obs.frame];
    ceres::ResidualBlockId id = nullptr;
    if (LensFree()) {
      auto* cost = new LensReprojectionCost{LensConstantsOf(), obs.px};
      id = problem_.AddResidualBlock(
          new ceres::AutoDiffCostFunction<LensReprojectionCost, 2, 7, 3,
                                          kLensSize>(cost),
          loss_, p.v, points_[i].data(), lens_.data());
    } else if (options_.refine_distortion) {
      id = problem_.AddResidualBlock(
          ReprojectionCost::CreateWithDistortion(intrinsics_, obs.px), loss_,
          p.v, points_[i].data(), distortion_.data());
    } else {
      id = problem_.AddResidualBlock(
          ReprojectionCost::Create(intrinsics_, obs.px), loss_, p.v,
          points_[i].data());
    }
    reprojection_blocks_.emplace_back(id, i);
    ++report_.num_residuals;
  }
}

void BundleAdjuster::AddOdometryPrior(int i, int j, double translation_fraction,
                                      double rotation_floor_deg,
                                      double rotation_deg_per_m) {
  const Rigid3d measured = odometry_[i].Inverse() * odometry_[j];
  const double length = measured.translation.norm();
  const double sigma_t =
      translation_fraction * length + options_.translation_sigma_floor_m;
  const double sigma_rot =
      DegToRad(rotation_floor_deg + rotation_deg_per_m * length);
  problem_.AddResidualBlock(
      new ceres::AutoDiffCostFunction<RelativePoseCost, 6, 7, 7>(
          new RelativePoseCost(measured, sigma_t, sigma_rot)),
      nullptr, poses_[i].v, poses_[j].v);
}

void BundleAdjuster::AddOdometryPriors() {
  for (int i = first_; i + 1 <= last_; ++i) {
    AddOdometryPrior(i, i + 1, options_.translation_sigma_fraction,
                     options_.rotation_sigma_floor_deg,
                     options_.rotation_sigma_deg_per_m);
    ++report_.num_priors;
  }
  if (options_.span_poses <= 0) return;
  for (int i = first_; i + options_.span_poses <= last_; ++i) {
    AddOdometryPrior(i, i + options_.span_poses,
                     options_.span_translation_sigma_fraction,
                     options_.span_rotation_sigma_deg, 0.0);
    ++report_.num_span_priors;
  }
}

void BundleAdjuster::AddPlanarBasePriors() {
  const PlanarBaseOptions& o = options_.planar_base;
  if (!o.enabled || !o.base_from_cam) return;
  for (int i = first_; i <= last_; ++i) {
    if (!problem_.HasParameterBlock(poses_[i].v)) continue;
    problem_.AddResidualBlock(
        new ceres::AutoDiffCostFunction<PlanarBaseCost, 3, 7>(
            new PlanarBaseCost(*o.base_from_cam, odometry_[i],
                               DegToRad(o.tilt_sigma_deg), o.height_sigma_m)),
        nullptr, poses_[i].v);
    ++report_.num_planar_priors;
  }
}

void BundleAdjuster::ParameterizePoses() {
  if (LensFree()) ParameterizeLens();
  for (int i = first_; i <= last_; ++i) {
    if (problem_.HasParameterBlock(poses_[i].v)) {
      problem_.SetManifold(poses_[i].v, new PoseManifold);
      ++report_.num_poses;
    }
  }
  if (!problem_.HasParameterBlock(poses_[first_].v)) return;
  if (options_.fix_first_pose) {
    problem_.SetParameterBlockConstant(poses_[first_].v);
  } else {
    problem_.AddResidualBlock(
        new ceres::AutoDiffCostFunction<AbsolutePoseCost, 6, 7>(
            new AbsolutePoseCost(cams_from_world_[first_],
                                 options_.translation_sigma_floor_m,
                                 DegToRad(options_.rotation_sigma_floor_deg))),
        nullptr, poses_[first_].v);
  }
}

ceres::Solver::Options BundleAdjuster::SetUpSolverOptions() {
  // Schur complement: eliminate the points first.
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  report_.num_points_joint = 0;  // called again after outlier removal
  for (Eigen::Vector3d& x : points_) {
    if (problem_.HasParameterBlock(x.data())) {
      ordering->AddElementToGroup(x.data(), 0);
      ++report_.num_points_joint;
    }
  }
  int num_pose_blocks = 0;
  for (int i = first_; i <= last_; ++i) {
    if (!problem_.HasParameterBlock(poses_[i].v)) continue;
    ordering->AddElementToGroup(poses_[i].v, 1);
    ++num_pose_blocks;
  }
  if (problem_.HasParameterBlock(distortion_.data())) {
    ordering->AddElementToGroup(distortion_.data(), 1);
    // equidistant has four coefficients: the fifth stays 0.
    if (intrinsics_.equidistant &&
        problem_.GetManifold(distortion_.data()) == nullptr) {
      problem_.SetManifold(distortion_.data(),
                           new ceres::SubsetManifold(5, {4}));
    }
  }
  if (problem_.HasParameterBlock(lens_.data())) {
    ordering->AddElementToGroup(lens_.data(), 1);
  }
  report_.covisibility =
      static_cast<double>(sum_squared_track_length_) / report_.num_residuals;
  // CG instead of the dense solver only: the sparse one is fast on its own.
  const bool dense = num_pose_blocks <= options_.dense_schur_max_poses;
  const bool iterative =
      options_.iterative_schur ||
      (dense && options_.iterative_schur_min_covisibility > 0.0 &&
       report_.covisibility > options_.iterative_schur_min_covisibility);
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = iterative ? ceres::ITERATIVE_SCHUR
                                      : dense   ? ceres::DENSE_SCHUR
                                                : ceres::SPARSE_SCHUR;
  if (iterative) {
    solver_options.preconditioner_type = ceres::SCHUR_JACOBI;
    solver_options.eta = options_.iterative_schur_eta;
  }
  report_.linear_solver =
      ceres::LinearSolverTypeToString(solver_options.linear_solver_type);
  solver_options.linear_solver_ordering = ordering;
  // Odometry is a good start, so begin close to Gauss-Newton: the strong
  // default damping stalls the weakly constrained directions (scale, which
  // only the priors hold) over many iterations.
  solver_options.initial_trust_region_radius = 1e8;
  solver_options.max_num_iterations = options_.max_num_iterations;
  solver_options.function_tolerance = options_.function_tolerance;
  solver_options.num_threads = options_.num_threads;
  solver_options.minimizer_progress_to_stdout = options_.verbose;
  solver_options.logging_type =
      options_.verbose ? ceres::PER_MINIMIZER_ITERATION : ceres::SILENT;
  return solver_options;
}

void BundleAdjuster::Solve(const ceres::Solver::Options& solver_options) {
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem_, &summary);
  if (options_.verbose) std::cout << summary.FullReport() << "\n";
  report_.iterations = static_cast<int>(summary.iterations.size());
  report_.termination =
      ceres::TerminationTypeToString(summary.termination_type);
  if (summary.termination_type == ceres::FAILURE) {
    throw StageError("bundle adjustment failed: " + summary.message);
  }
  // From here on (landmarks refined alone, errors, filtering) the refined
  // lens.
  if (LensFree()) {
    adjusted_camera_ =
        WithLens(camera_, lens_, options_.intrinsics.shared_focal);
  } else {
    adjusted_camera_.distortion = distortion_;
  }
  report_.distortion = adjusted_camera_.distortion;
  report_.camera = adjusted_camera_;
}

int BundleAdjuster::RemoveOutlierObservations(double threshold_px) {
  std::vector<int> left(points_.size(), 0);
  std::vector<std::pair<ceres::ResidualBlockId, size_t>> kept;
  int removed = 0;
  for (const auto& [id, i] : reprojection_blocks_) {
    double cost = 0.0;
    double residual[2];
    // A residual that cannot be evaluated (point behind the camera) counts
    // as an outlier.
    const bool ok =
        problem_.EvaluateResidualBlock(id, false, &cost, residual, nullptr);
    if (ok && std::hypot(residual[0], residual[1]) <= threshold_px) {
      ++left[i];
      kept.emplace_back(id, i);
      continue;
    }
    problem_.RemoveResidualBlock(id);
    ++removed;
  }
  reprojection_blocks_.clear();
  for (const auto& [id, i] : kept) {
    if (left[i] >= 2) reprojection_blocks_.emplace_back(id, i);
  }
  // A point seen once has no depth: out of the joint problem (with its last
  // observation); RefineOtherLandmarks refines it alone. (Points that never
  // entered the problem, behind a camera, stay as they were.)
  for (size_t i = 0; i < points_.size(); ++i) {
    if (!joint_[i] || left[i] >= 2 ||
        !problem_.HasParameterBlock(points_[i].data())) {
      continue;
    }
    problem_.RemoveParameterBlock(points_[i].data());
    joint_[i] = 0;
    ++report_.num_outlier_points;
  }
  report_.num_outlier_observations += removed;
  return removed;
}

void BundleAdjuster::WriteBackPoses(std::vector<Rigid3d>* world_from_cam) {
  std::vector<Rigid3d>& w = *world_from_cam;
  for (int i = first_; i <= last_; ++i) w[i] = FromParams(poses_[i]).Inverse();
  // Frames outside the adjusted range follow their nearest adjusted frame
  // by the odometry motion, so the trajectory stays continuous.
  for (int i = last_ + 1; i < num_frames_; ++i) {
    w[i] = w[last_] * (odometry_[last_].Inverse() * odometry_[i]);
  }
  for (int i = first_ - 1; i >= 0; --i) {
    w[i] = w[first_] * (odometry_[first_].Inverse() * odometry_[i]);
  }
  double sum_change_m = 0.0, sum_change_rad = 0.0;
  for (int i = 0; i < num_frames_; ++i) {
    cams_from_world_[i] = w[i].Inverse();
    sum_change_m += (w[i].translation - odometry_[i].translation).norm();
    sum_change_rad += AngleBetween(w[i].rotation, odometry_[i].rotation);
  }
  report_.mean_pose_change_m = sum_change_m / num_frames_;
  report_.mean_pose_change_deg = RadToDeg(sum_change_rad / num_frames_);
}

void BundleAdjuster::RefineOtherLandmarks() {
  // Landmarks left out of the joint problem: refined alone with the
  // adjusted poses held fixed.
  const TriangulationOptions refine_options;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, points_.size(), 64),
                    [&](const tbb::blocked_range<size_t>& range) {
                      for (size_t i = range.begin(); i != range.end(); ++i) {
                        if (joint_[i] || !points_[i].allFinite()) continue;
                        RefinePoint(adjusted_camera_, cams_from_world_,
                                    *landmark_tracks_[i], refine_options,
                                    &points_[i]);
                      }
                    });
  RmsAndMedian(ReprojectionErrors(adjusted_camera_, cams_from_world_,
                                  landmark_tracks_, points_),
               &report_.final_rms_error_px, &report_.final_median_error_px);
}

void BundleAdjuster::UpdateLandmarks(std::vector<Landmark>* landmarks) {
  // Drop the landmarks bundle adjustment could not reconcile.
  std::vector<Landmark> kept;
  kept.reserve(landmarks->size());
  for (size_t i = 0; i < landmarks->size(); ++i) {
    Landmark l = (*landmarks)[i];
    const PointStatistics s = EvaluatePoint(adjusted_camera_, cams_from_world_,
                                            *landmark_tracks_[i], points_[i]);
    if (!points_[i].allFinite() ||
        s.mean_error_px > options_.max_reprojection_error_px ||
        s.min_depth_m < options_.min_depth_m) {
      ++report_.num_dropped;
      continue;
    }
    l.x_in_world = points_[i];
    l.num_observations =
        static_cast<int>(landmark_tracks_[i]->observations.size());
    l.mean_reprojection_error_px = s.mean_error_px;
    l.triangulation_angle_deg = s.triangulation_angle_deg;
    l.mean_depth_m = s.mean_distance_m;
    l.covariance_m2_per_px2 = s.covariance_m2_per_px2;
    kept.push_back(l);
  }
  *landmarks = std::move(kept);
}

void BundleAdjuster::SetFreeLensGroups(
    const std::array<bool, kNumLensGroups>& groups) {
  free_groups_ = groups;
}

// Parameters of the lens block held constant: those of the fixed groups,
// and fy when it follows fx.
std::vector<int> FixedLensParameters(
    const std::array<bool, kNumLensGroups>& free_groups, bool shared_focal) {
  std::vector<int> fixed;
  if (!free_groups[kGroupFocal]) fixed = {kLensFx, kLensFy};
  if (free_groups[kGroupFocal] && shared_focal) fixed.push_back(kLensFy);
  if (!free_groups[kGroupPrincipalPoint]) {
    fixed.insert(fixed.end(), {kLensCx, kLensCy});
  }
  if (!free_groups[kGroupRadial]) fixed.insert(fixed.end(), {kLensK1, kLensK2});
  if (!free_groups[kGroupK3]) fixed.push_back(kLensK3);
  return fixed;
}

void BundleAdjuster::ParameterizeLens() {
  if (!problem_.HasParameterBlock(lens_.data())) return;
  internal::LensPriorCost* prior = new internal::LensPriorCost;
  prior->given = LensParameters(camera_);
  const auto sigmas = LensPriorSigmas(camera_, options_.intrinsics);
  for (int k = 0; k < kLensSize; ++k) prior->inv_sigma[k] = 1.0 / sigmas[k];
  problem_.AddResidualBlock(
      new ceres::AutoDiffCostFunction<internal::LensPriorCost, kLensSize,
                                      kLensSize>(prior),
      nullptr, lens_.data());
  const std::vector<int> fixed =
      FixedLensParameters(free_groups_, options_.intrinsics.shared_focal);
  if (!fixed.empty()) {
    problem_.SetManifold(lens_.data(),
                         new ceres::SubsetManifold(kLensSize, fixed));
  }
}

bool BundleAdjuster::LensStandardDeviations(
    std::array<double, kLensSize>* stds) {
  stds->fill(0.0);
  if (!problem_.HasParameterBlock(lens_.data())) return false;
  // Marginal covariance of the lens block: the lens rows of the inverse of
  // J^T J (Gauss-Newton Hessian, robust weights applied) over every free
  // pose and point, by a sparse Cholesky factorization. The lens block
  // comes first, so its tangent coordinates are the first columns.
  ceres::Problem::EvaluateOptions evaluate;
  evaluate.parameter_blocks = {lens_.data()};
  std::vector<double*> blocks;
  problem_.GetParameterBlocks(&blocks);
  for (double* b : blocks) {
    if (b != lens_.data() && !problem_.IsParameterBlockConstant(b)) {
      evaluate.parameter_blocks.push_back(b);
    }
  }
  evaluate.num_threads = options_.num_threads;
  ceres::CRSMatrix crs;
  if (!problem_.Evaluate(evaluate, nullptr, nullptr, nullptr, &crs)) {
    return false;
  }
  const Eigen::Map<const Eigen::SparseMatrix<double, Eigen::RowMajor>> j(
      crs.num_rows, crs.num_cols, static_cast<int>(crs.values.size()),
      crs.rows.data(), crs.cols.data(), crs.values.data());
  const Eigen::SparseMatrix<double> h = j.transpose() * j;
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(h);
  if (ldlt.info() != Eigen::Success) return false;
  const std::vector<int> fixed =
      FixedLensParameters(free_groups_, options_.intrinsics.shared_focal);
  int column = 0;
  for (int k = 0; k < kLensSize; ++k) {
    if (std::find(fixed.begin(), fixed.end(), k) != fixed.end()) continue;
    const Eigen::VectorXd x =
        ldlt.solve(Eigen::VectorXd::Unit(crs.num_cols, column));
    if (ldlt.info() != Eigen::Success || !(x[column] > 0.0)) return false;
    (*stds)[k] = std::sqrt(x[column]);
    ++column;
  }
  return true;
}

}  // namespace

void PlanarBaseOptions::Check() const {
  CheckOption(tilt_sigma_deg > 0, "planar_base.tilt_sigma_deg",
              "must be positive");
  CheckOption(height_sigma_m > 0, "planar_base.height_sigma_m",
              "must be positive");
}

void BundleAdjustmentOptions::Check() const {
  planar_base.Check();
  CheckOption(loss == "huber" || loss == "cauchy" || loss == "none", "loss",
              "must be huber, cauchy or none");
  CheckOption(loss_scale_px > 0, "loss_scale_px", "must be positive");
  CheckOption(outlier_threshold_px >= 0, "outlier_threshold_px",
              "must be non-negative");
  CheckOption(translation_sigma_fraction >= 0, "translation_sigma_fraction",
              "must be >= 0");
  CheckOption(translation_sigma_floor_m > 0, "translation_sigma_floor_m",
              "must be positive");
  CheckOption(rotation_sigma_floor_deg > 0, "rotation_sigma_floor_deg",
              "must be positive");
  CheckOption(rotation_sigma_deg_per_m >= 0, "rotation_sigma_deg_per_m",
              "must be >= 0");
  CheckOption(span_poses >= 0, "span_poses", "must be >= 0 (0: off)");
  CheckOption(span_rotation_sigma_deg > 0, "span_rotation_sigma_deg",
              "must be positive");
  CheckOption(span_translation_sigma_fraction >= 0,
              "span_translation_sigma_fraction", "must be >= 0");
  CheckOption(max_points >= 0, "max_points", "must be >= 0");
  CheckOption(max_num_iterations >= 0, "max_num_iterations", "must be >= 0");
  CheckOption(function_tolerance > 0, "function_tolerance", "must be positive");
  CheckOption(num_threads >= 1, "num_threads", "must be >= 1");
  CheckOption(dense_schur_max_poses >= 0, "dense_schur_max_poses",
              "must be >= 0");
  CheckOption(iterative_schur_eta > 0 && iterative_schur_eta < 1,
              "iterative_schur_eta", "must be in (0, 1)");
  CheckOption(max_reprojection_error_px > 0, "max_reprojection_error_px",
              "must be positive");
  CheckOption(min_depth_m > 0, "min_depth_m", "must be positive");
  intrinsics.Check();
  CheckOption(!(refine_distortion && intrinsics.enabled), "refine_distortion",
              "and intrinsics.enabled exclude each other (both refine the "
              "distortion)");
}

namespace {

// The trial adjustment's lens block: marginal standard deviations,
// candidate values and the judgement of each group, into *lens.
void JudgeTrialLens(const Camera& camera,
                    const BundleAdjustmentOptions& options,
                    BundleAdjuster* adjuster,
                    IntrinsicsRefinementReport* lens) {
  const Timer timer;
  const bool ok = adjuster->LensStandardDeviations(&lens->posterior_std);
  if (!ok) lens->posterior_std.fill(-1.0);
  lens->candidate = adjuster->lens();
  lens->prior_std = LensPriorSigmas(camera, options.intrinsics);
  if (options.intrinsics.shared_focal) lens->prior_std[kLensFy] = 0.0;
  JudgeLensGroups(options.intrinsics, ok, lens);
  lens->covariance_seconds = timer.ElapsedSeconds();
}

// One adjustment with the given lens groups free (none: lens fixed). With
// `lens` (the trial of self-calibration), the lens block is judged after
// the solve (JudgeTrialLens); if it rejects a free group, nothing is
// written back and false is returned: the caller adjusts again with the
// accepted groups only.
bool AdjustOnce(const Camera& camera, const std::vector<Track>& tracks,
                const BundleAdjustmentOptions& options,
                const std::array<bool, kNumLensGroups>& free_groups,
                IntrinsicsRefinementReport* lens,
                std::vector<Rigid3d>* world_from_cam,
                std::vector<Landmark>* landmarks,
                BundleAdjustmentReport* report) {
  const Timer timer;
  *report = BundleAdjustmentReport();
  report->distortion = camera.distortion;
  report->camera = camera;
  report->num_points = static_cast<int>(landmarks->size());
  const int num_frames = static_cast<int>(world_from_cam->size());
  BundleAdjuster adjuster(camera, options,
                          MatchLandmarkTracks(tracks, *landmarks, num_frames),
                          *world_from_cam, *landmarks, report);
  adjuster.SetFreeLensGroups(free_groups);
  const bool nothing_to_adjust = landmarks->empty() || num_frames == 0;
  if (!options.enabled || nothing_to_adjust || !adjuster.SetUpProblem()) {
    if (options.enabled && !nothing_to_adjust) {
      // Every landmark was behind a camera: all dropped.
      report->num_dropped = static_cast<int>(landmarks->size());
      landmarks->clear();
    }
    report->final_rms_error_px = report->initial_rms_error_px;
    report->final_median_error_px = report->initial_median_error_px;
    report->termination = options.enabled ? "nothing to adjust" : "disabled";
    report->seconds = timer.ElapsedSeconds();
    if (lens) lens->reason = "lens kept: nothing to adjust";
    return true;
  }
  adjuster.AddOdometryPriors();
  adjuster.AddPlanarBasePriors();
  adjuster.ParameterizePoses();
  adjuster.Solve(adjuster.SetUpSolverOptions());
  if (options.outlier_threshold_px > 0 &&
      adjuster.RemoveOutlierObservations(options.outlier_threshold_px) > 0) {
    adjuster.Solve(adjuster.SetUpSolverOptions());
  }
  if (lens) {
    JudgeTrialLens(camera, options, &adjuster, lens);
    if (lens->group_refined != free_groups) return false;
  }
  adjuster.WriteBackPoses(world_from_cam);
  adjuster.RefineOtherLandmarks();
  adjuster.UpdateLandmarks(landmarks);
  report->seconds = timer.ElapsedSeconds();
  return true;
}

// The lens trial on frames [first, last) alone: the tracks cut to those
// frames (kept with >= 3 observations there) and their landmarks, on
// copies. Returns the trial's values and marginal standard deviations.
IntrinsicsRefinementReport TrialOnFrames(
    const Camera& camera, const std::vector<Track>& tracks,
    const BundleAdjustmentOptions& options,
    const std::array<bool, kNumLensGroups>& free_groups, int first, int last,
    std::vector<Rigid3d> world_from_cam,
    const std::vector<Landmark>& landmarks) {
  std::vector<Track> cut;
  std::unordered_map<FeatureId, bool> kept;
  for (const Track& t : tracks) {
    Track c{t.id, {}};
    for (const Observation& o : t.observations) {
      if (o.frame >= first && o.frame < last) c.observations.push_back(o);
    }
    if (c.observations.size() < 3) continue;
    kept[t.id] = true;
    cut.push_back(std::move(c));
  }
  std::vector<Landmark> cut_landmarks;
  for (const Landmark& l : landmarks) {
    if (kept.count(l.id)) cut_landmarks.push_back(l);
  }
  IntrinsicsRefinementReport lens;
  lens.before = camera;
  BundleAdjustmentReport report;
  AdjustOnce(camera, cut, options, free_groups, &lens, &world_from_cam,
             &cut_landmarks, &report);
  return lens;
}

// check_halves: the trials on each half of the frames, into *lens for the
// judgement of the whole trial (JudgeLensGroups).
void TrialOnHalves(const Camera& camera, const std::vector<Track>& tracks,
                   const BundleAdjustmentOptions& options,
                   const std::array<bool, kNumLensGroups>& free_groups,
                   const std::vector<Rigid3d>& world_from_cam,
                   const std::vector<Landmark>& landmarks,
                   IntrinsicsRefinementReport* lens) {
  const int n = static_cast<int>(world_from_cam.size());
  const int bounds[3] = {0, n / 2, n};
  for (int h = 0; h < 2; ++h) {
    const IntrinsicsRefinementReport half =
        TrialOnFrames(camera, tracks, options, free_groups, bounds[h],
                      bounds[h + 1], world_from_cam, landmarks);
    lens->halves_candidate[h] = half.candidate;
    lens->halves_std[h] = half.posterior_std;
  }
  lens->halves_checked = true;
}

}  // namespace

BundleAdjustmentReport BundleAdjust(const Camera& camera,
                                    const std::vector<Track>& tracks,
                                    const BundleAdjustmentOptions& options,
                                    std::vector<Rigid3d>* world_from_cam,
                                    std::vector<Landmark>* landmarks) {
  options.Check();
  camera.Check();
  const Timer timer;
  IntrinsicsRefinementReport lens;
  lens.before = camera;
  const IntrinsicsRefinementOptions& io = options.intrinsics;
  BundleAdjustmentReport report;
  bool done = false;
  if (options.enabled && io.enabled) {
    // Trial with the chosen groups free under their prior; kept if every
    // group passes the judgement, else adjusted again without the others.
    lens.attempted = true;
    const std::array<bool, kNumLensGroups> wanted = {
        io.refine_focal, io.refine_principal_point, io.refine_radial,
        io.refine_k3};
    if (io.check_halves) {
      TrialOnHalves(camera, tracks, options, wanted, *world_from_cam,
                    *landmarks, &lens);
    }
    done = AdjustOnce(camera, tracks, options, wanted, &lens, world_from_cam,
                      landmarks, &report);
  }
  if (!done) {
    AdjustOnce(camera, tracks, options, lens.group_refined, nullptr,
               world_from_cam, landmarks, &report);
  }
  lens.after = report.camera;
  report.intrinsics = lens;
  report.seconds = timer.ElapsedSeconds();
  return report;
}

}  // namespace monomap
