#include "monomap/triangulation/bundle_adjustment.h"

#include <ceres/ceres.h>
#include <ceres/manifold.h>
#include <ceres/product_manifold.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <map>
#include <memory>
#include <unordered_map>

#include "monomap/geometry/triangulation.h"
#include "monomap/triangulation/projection.h"
#include "monomap/triangulation/triangulator.h"
#include "monomap/util/error.h"
#include "monomap/util/progress.h"

namespace monomap {
namespace {

constexpr double kDegToRad = M_PI / 180.0;
constexpr double kRadToDeg = 180.0 / M_PI;

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

  template <typename T, typename D>
  bool Residual(const T* pose, const T* x, const D* distortion,
                T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> rotation(pose);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> translation(pose + 4);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> x_in_world(x);
    const Eigen::Matrix<T, 3, 1> x_in_cam = rotation * x_in_world + translation;
    // A point crossing the image plane has no projection: reject the step.
    if (!(x_in_cam.z() > T(1e-6))) return false;
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
  std::nth_element(errors.begin(), errors.begin() + errors.size() / 2,
                   errors.end());
  *median = errors[errors.size() / 2];
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

}  // namespace

void BundleAdjustmentOptions::Check() const {
  CheckOption(loss == "huber" || loss == "cauchy" || loss == "none", "loss",
              "must be huber, cauchy or none");
  CheckOption(loss_scale_px > 0, "loss_scale_px", "must be positive");
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
}

BundleAdjustmentReport BundleAdjust(const Camera& camera,
                                    const std::vector<Track>& tracks,
                                    const BundleAdjustmentOptions& options,
                                    std::vector<Rigid3d>* world_from_cam,
                                    std::vector<Landmark>* landmarks) {
  options.Check();
  camera.Check();
  const Timer timer;
  BundleAdjustmentReport report;
  report.distortion = camera.distortion;
  const int num_frames = static_cast<int>(world_from_cam->size());

  // Match landmarks to their tracks by id.
  std::unordered_map<FeatureId, const Track*> track_by_id;
  track_by_id.reserve(tracks.size());
  for (const Track& track : tracks) track_by_id.emplace(track.id, &track);
  std::vector<const Track*> landmark_tracks;
  landmark_tracks.reserve(landmarks->size());
  for (const Landmark& l : *landmarks) {
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

  const std::vector<Rigid3d> odometry = *world_from_cam;
  std::vector<PoseParams> poses(num_frames);
  std::vector<Rigid3d> cams_from_world(num_frames);
  for (int i = 0; i < num_frames; ++i) {
    cams_from_world[i] = odometry[i].Inverse();
    poses[i] = ToParams(cams_from_world[i]);
  }
  std::vector<Eigen::Vector3d> points(landmarks->size());
  for (size_t i = 0; i < landmarks->size(); ++i) {
    points[i] = (*landmarks)[i].x_in_world;
  }
  RmsAndMedian(
      ReprojectionErrors(camera, cams_from_world, landmark_tracks, points),
      &report.initial_rms_error_px, &report.initial_median_error_px);
  report.num_points = static_cast<int>(landmarks->size());

  if (!options.enabled || landmarks->empty() || num_frames == 0) {
    report.final_rms_error_px = report.initial_rms_error_px;
    report.final_median_error_px = report.initial_median_error_px;
    report.termination = options.enabled ? "nothing to adjust" : "disabled";
    report.seconds = timer.ElapsedSeconds();
    return report;
  }

  ceres::Problem problem;
  const internal::Intrinsics intrinsics(camera);
  ceres::LossFunction* loss = nullptr;
  if (options.loss == "huber") {
    loss = new ceres::HuberLoss(options.loss_scale_px);
  } else if (options.loss == "cauchy") {
    loss = new ceres::CauchyLoss(options.loss_scale_px);
  }
  const std::vector<char> joint =
      SelectJointPoints(landmark_tracks, options.max_points);
  // k1, k2, p1, p2, k3; a parameter block only with refine_distortion.
  std::array<double, 5> distortion = camera.distortion;
  std::vector<bool> observed(num_frames, false);
  int64_t sum_squared_track_length = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    if (!joint[i]) continue;
    // A point behind one of its cameras has no valid residual (Ceres would
    // fail at the first evaluation): leave it out; it is dropped below.
    bool in_front = points[i].allFinite();
    for (const Observation& obs : landmark_tracks[i]->observations) {
      in_front = in_front &&
                 DepthInCamera(cams_from_world[obs.frame], points[i]) > 1e-6;
    }
    if (!in_front) continue;
    const int64_t k =
        static_cast<int64_t>(landmark_tracks[i]->observations.size());
    sum_squared_track_length += k * k;
    for (const Observation& obs : landmark_tracks[i]->observations) {
      PoseParams& p = poses[obs.frame];
      if (options.refine_distortion) {
        problem.AddResidualBlock(
            ReprojectionCost::CreateWithDistortion(intrinsics, obs.px), loss,
            p.v, points[i].data(), distortion.data());
      } else {
        problem.AddResidualBlock(ReprojectionCost::Create(intrinsics, obs.px),
                                 loss, p.v, points[i].data());
      }
      observed[obs.frame] = true;
      ++report.num_residuals;
    }
  }
  if (report.num_residuals == 0) {
    // Every landmark was behind a camera: nothing to adjust, all dropped.
    report.num_dropped = static_cast<int>(landmarks->size());
    landmarks->clear();
    delete loss;
    report.final_rms_error_px = report.initial_rms_error_px;
    report.final_median_error_px = report.initial_median_error_px;
    report.termination = "nothing to adjust";
    report.seconds = timer.ElapsedSeconds();
    return report;
  }
  // Every frame between the first and last observed one takes part, tied by
  // the odometry priors; frames outside are left as they are.
  int first = 0, last = num_frames - 1;
  while (first < num_frames && !observed[first]) ++first;
  while (last > first && !observed[last]) --last;
  // With the first pose as gauge, the chain must start there.
  if (options.fix_first_pose) first = 0;
  // Odometry prior on the relative pose of poses i and j.
  auto add_prior = [&](int i, int j, double translation_fraction,
                       double rotation_floor_deg, double rotation_deg_per_m) {
    const Rigid3d measured = odometry[i].Inverse() * odometry[j];
    const double length = measured.translation.norm();
    const double sigma_t =
        translation_fraction * length + options.translation_sigma_floor_m;
    const double sigma_rot =
        (rotation_floor_deg + rotation_deg_per_m * length) * kDegToRad;
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<RelativePoseCost, 6, 7, 7>(
            new RelativePoseCost(measured, sigma_t, sigma_rot)),
        nullptr, poses[i].v, poses[j].v);
  };
  for (int i = first; i + 1 <= last; ++i) {
    add_prior(i, i + 1, options.translation_sigma_fraction,
              options.rotation_sigma_floor_deg,
              options.rotation_sigma_deg_per_m);
    ++report.num_priors;
  }
  if (options.span_poses > 0) {
    for (int i = first; i + options.span_poses <= last; ++i) {
      add_prior(i, i + options.span_poses,
                options.span_translation_sigma_fraction,
                options.span_rotation_sigma_deg, 0.0);
      ++report.num_span_priors;
    }
  }
  for (int i = first; i <= last; ++i) {
    if (problem.HasParameterBlock(poses[i].v)) {
      problem.SetManifold(poses[i].v, new PoseManifold);
      ++report.num_poses;
    }
  }
  if (problem.HasParameterBlock(poses[first].v)) {
    if (options.fix_first_pose) {
      problem.SetParameterBlockConstant(poses[first].v);
    } else {
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<AbsolutePoseCost, 6, 7>(
              new AbsolutePoseCost(
                  cams_from_world[first], options.translation_sigma_floor_m,
                  options.rotation_sigma_floor_deg * kDegToRad)),
          nullptr, poses[first].v);
    }
  }

  // Schur complement: eliminate the points first.
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  for (Eigen::Vector3d& x : points) {
    if (problem.HasParameterBlock(x.data())) {
      ordering->AddElementToGroup(x.data(), 0);
      ++report.num_points_joint;
    }
  }
  for (int i = first; i <= last; ++i) {
    if (!problem.HasParameterBlock(poses[i].v)) continue;
    ordering->AddElementToGroup(poses[i].v, 1);
  }
  if (problem.HasParameterBlock(distortion.data())) {
    ordering->AddElementToGroup(distortion.data(), 1);
  }

  ceres::Solver::Options solver_options;
  int num_pose_blocks = 0;
  for (int i = first; i <= last; ++i) {
    num_pose_blocks += problem.HasParameterBlock(poses[i].v) ? 1 : 0;
  }
  report.covisibility = report.num_residuals > 0
                            ? static_cast<double>(sum_squared_track_length) /
                                  report.num_residuals
                            : 0.0;
  // CG instead of the dense solver only: the sparse one is fast on its own.
  const bool dense = num_pose_blocks <= options.dense_schur_max_poses;
  const bool iterative =
      options.iterative_schur ||
      (dense && options.iterative_schur_min_covisibility > 0.0 &&
       report.covisibility > options.iterative_schur_min_covisibility);
  solver_options.linear_solver_type =
      iterative ? ceres::ITERATIVE_SCHUR
      : dense   ? ceres::DENSE_SCHUR
                : ceres::SPARSE_SCHUR;
  if (iterative) {
    solver_options.preconditioner_type = ceres::SCHUR_JACOBI;
    solver_options.eta = options.iterative_schur_eta;
  }
  report.linear_solver =
      ceres::LinearSolverTypeToString(solver_options.linear_solver_type);
  solver_options.linear_solver_ordering = ordering;
  // Odometry is a good start, so begin close to Gauss-Newton: the strong
  // default damping stalls the weakly constrained directions (scale, which
  // only the priors hold) over many iterations.
  solver_options.initial_trust_region_radius = 1e8;
  solver_options.max_num_iterations = options.max_num_iterations;
  solver_options.function_tolerance = options.function_tolerance;
  solver_options.num_threads = options.num_threads;
  solver_options.minimizer_progress_to_stdout = options.verbose;
  solver_options.logging_type =
      options.verbose ? ceres::PER_MINIMIZER_ITERATION : ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  if (options.verbose) std::cout << summary.FullReport() << "\n";
  report.iterations = static_cast<int>(summary.iterations.size());
  report.termination = ceres::TerminationTypeToString(summary.termination_type);
  if (summary.termination_type == ceres::FAILURE) {
    throw StageError("bundle adjustment failed: " + summary.message);
  }
  // From here on (landmarks refined alone, errors, filtering) the refined
  // lens.
  Camera adjusted_camera = camera;
  adjusted_camera.distortion = distortion;
  report.distortion = distortion;

  // Write back poses and their change.
  double sum_change_m = 0.0, sum_change_rad = 0.0;
  for (int i = first; i <= last; ++i) {
    (*world_from_cam)[i] = FromParams(poses[i]).Inverse();
  }
  // Frames outside the adjusted range follow their nearest adjusted frame
  // by the odometry motion, so the trajectory stays continuous.
  for (int i = last + 1; i < num_frames; ++i) {
    (*world_from_cam)[i] =
        (*world_from_cam)[last] * (odometry[last].Inverse() * odometry[i]);
  }
  for (int i = first - 1; i >= 0; --i) {
    (*world_from_cam)[i] =
        (*world_from_cam)[first] * (odometry[first].Inverse() * odometry[i]);
  }
  for (int i = 0; i < num_frames; ++i) {
    cams_from_world[i] = (*world_from_cam)[i].Inverse();
    sum_change_m +=
        ((*world_from_cam)[i].translation - odometry[i].translation).norm();
    sum_change_rad +=
        AngleBetween((*world_from_cam)[i].rotation, odometry[i].rotation);
  }
  report.mean_pose_change_m = sum_change_m / num_frames;
  report.mean_pose_change_deg = sum_change_rad / num_frames * kRadToDeg;

  // Landmarks left out of the joint problem: refined alone with the
  // adjusted poses held fixed.
  const TriangulationOptions refine_options;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, points.size(), 64),
                    [&](const tbb::blocked_range<size_t>& range) {
                      for (size_t i = range.begin(); i != range.end(); ++i) {
                        if (joint[i] || !points[i].allFinite()) continue;
                        RefinePoint(adjusted_camera, cams_from_world,
                                    *landmark_tracks[i], refine_options,
                                    &points[i]);
                      }
                    });

  RmsAndMedian(ReprojectionErrors(adjusted_camera, cams_from_world,
                                  landmark_tracks, points),
               &report.final_rms_error_px, &report.final_median_error_px);

  // Update landmarks; drop the ones bundle adjustment could not reconcile.
  std::vector<Landmark> kept;
  kept.reserve(landmarks->size());
  for (size_t i = 0; i < landmarks->size(); ++i) {
    Landmark l = (*landmarks)[i];
    const PointStatistics s = EvaluatePoint(adjusted_camera, cams_from_world,
                                            *landmark_tracks[i], points[i]);
    if (!points[i].allFinite() ||
        s.mean_error_px > options.max_reprojection_error_px ||
        s.min_depth_m < options.min_depth_m) {
      ++report.num_dropped;
      continue;
    }
    l.x_in_world = points[i];
    l.num_observations =
        static_cast<int>(landmark_tracks[i]->observations.size());
    l.mean_reprojection_error_px = s.mean_error_px;
    l.triangulation_angle_deg = s.triangulation_angle_deg;
    l.mean_depth_m = s.mean_distance_m;
    l.covariance_m2_per_px2 = s.covariance_m2_per_px2;
    kept.push_back(l);
  }
  *landmarks = std::move(kept);
  report.seconds = timer.ElapsedSeconds();
  return report;
}

}  // namespace monomap
