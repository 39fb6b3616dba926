#include "monomap/eval/board_poses.h"

#include <tbb/parallel_for.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>

#include "monomap/camera/calibration.h"
#include "monomap/util/angles.h"
#include "monomap/util/error.h"

namespace monomap {

void BoardPoseOptions::Check() const {
  CheckOption(max_rms_px > 0.0, "max_rms_px", "must be > 0");
  CheckOption(subpix_half_window >= 1, "subpix_half_window", "must be >= 1");
}

namespace {

// cam_from_world from OpenCV's rvec/tvec and back.
Rigid3d FromRvecTvec(const cv::Mat& rvec, const cv::Mat& tvec) {
  cv::Mat r;
  cv::Rodrigues(rvec, r);
  Eigen::Matrix3d rotation;
  cv::cv2eigen(r, rotation);
  return Rigid3d(Eigen::Quaterniond(rotation),
                 Eigen::Vector3d(tvec.at<double>(0), tvec.at<double>(1),
                                 tvec.at<double>(2)));
}

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d s;
  s << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return s;
}

// J_l(phi) of SO(3): exp(phi + d) = exp(J_l(phi) d) exp(phi) to first order.
Eigen::Matrix3d LeftJacobianSo3(const Eigen::Vector3d& phi) {
  const double theta = phi.norm();
  const Eigen::Matrix3d s = Skew(phi);
  if (theta < 1e-8) return Eigen::Matrix3d::Identity() + 0.5 * s;
  const double t2 = theta * theta;
  return Eigen::Matrix3d::Identity() + (1.0 - std::cos(theta)) / t2 * s +
         (theta - std::sin(theta)) / (t2 * theta) * s * s;
}

// The formal standard deviations of a PnP pose (pose->world_from_cam set)
// from the projection Jacobian and the residuals' sum of squares.
void SetFormalSigmas(const cv::Mat& jacobian, double sum_sq,
                     size_t num_corners, const cv::Mat& rvec,
                     const cv::Mat& tvec, BoardPose* pose) {
  const Rigid3d& world_from_cam = pose->world_from_cam;
  // Covariance of (rvec, tvec): sigma^2 (J^T J)^-1 with sigma from the
  // residuals (2n - 6 degrees of freedom). A step d in rvec rotates the
  // camera by w = Jl(rvec) d (SO(3)'s left Jacobian); the camera centre
  // c = -R^T t then moves by -R^T dt - R^T [t]x w.
  Eigen::MatrixXd j;
  cv::cv2eigen(jacobian.colRange(0, 6), j);
  const double dof = 2.0 * static_cast<double>(num_corners) - 6.0;
  const Eigen::Matrix<double, 6, 6> cov =
      (sum_sq / dof) *
      (j.transpose() * j).ldlt().solve(Eigen::MatrixXd::Identity(6, 6));
  const Eigen::Vector3d phi(rvec.at<double>(0), rvec.at<double>(1),
                            rvec.at<double>(2));
  const Eigen::Matrix3d left_jacobian = LeftJacobianSo3(phi);
  const Eigen::Matrix3d rot_cov =
      left_jacobian * cov.topLeftCorner<3, 3>() * left_jacobian.transpose();
  pose->rotation_sigma_deg = RadToDeg(std::sqrt(
      std::max(0.0, Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(rot_cov)
                        .eigenvalues()
                        .maxCoeff())));
  const Eigen::Vector3d t(tvec.at<double>(0), tvec.at<double>(1),
                          tvec.at<double>(2));
  const Eigen::Matrix3d rt = world_from_cam.RotationMatrix();
  Eigen::Matrix<double, 3, 6> dc;  // d(centre) / d(rvec, tvec)
  dc.leftCols<3>() = -rt * Skew(t) * left_jacobian;
  dc.rightCols<3>() = -rt;
  pose->position_sigma_m =
      std::sqrt(std::max(0.0, Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(
                                  dc * cov * dc.transpose())
                                  .eigenvalues()
                                  .maxCoeff()));
}

}  // namespace

std::optional<BoardPose> EstimateBoardPose(const cv::Mat& grey,
                                           const Camera& camera,
                                           const CheckerboardSpec& spec,
                                           const Rigid3d& hint_world_from_cam,
                                           const BoardPoseOptions& options) {
  options.Check();
  // OpenCV's solvePnP below knows the plumb_bob polynomial only.
  CheckOption(camera.model == LensModel::kPlumbBob, "camera.distortion_model",
              "board poses need a plumb_bob camera (equidistant is not "
              "supported here)");
  const std::optional<std::vector<cv::Point2f>> detected =
      DetectCheckerboardCorners(grey, spec.inner_corners_x,
                                spec.inner_corners_y,
                                options.subpix_half_window);
  if (!detected) return std::nullopt;
  const std::vector<cv::Point2f>& corners = *detected;

  const cv::Matx33d k(camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0,
                      1);
  const std::vector<double> dist(camera.distortion.begin(),
                                 camera.distortion.end());
  const int nx = spec.inner_corners_x, ny = spec.inner_corners_y;
  std::vector<cv::Point3d> object(corners.size());
  std::optional<BoardPose> best;
  double best_angle = std::numeric_limits<double>::infinity();
  double best_rms = std::numeric_limits<double>::infinity();
  // OpenCV lists the corners row by row from any of the board's corners:
  // try the start at either end of either axis.
  for (int flip = 0; flip < 4; ++flip) {
    for (int k_index = 0; k_index < static_cast<int>(corners.size());
         ++k_index) {
      int i = k_index % nx, j = k_index / nx;
      if (flip & 1) i = nx - 1 - i;
      if (flip & 2) j = ny - 1 - j;
      const Eigen::Vector3d x = spec.Corner(i, j);
      object[k_index] = cv::Point3d(x.x(), x.y(), x.z());
    }
    cv::Mat rvec, tvec;
    if (!cv::solvePnP(object, corners, k, dist, rvec, tvec, false,
                      cv::SOLVEPNP_IPPE)) {
      continue;
    }
    cv::solvePnPRefineLM(object, corners, k, dist, rvec, tvec);
    std::vector<cv::Point2d> projected;
    cv::Mat jacobian;
    cv::projectPoints(object, rvec, tvec, k, dist, projected, jacobian);
    std::vector<double> errors(corners.size());
    double sum_sq = 0.0;
    for (size_t n = 0; n < corners.size(); ++n) {
      const cv::Point2d d = projected[n] - cv::Point2d(corners[n]);
      errors[n] = std::hypot(d.x, d.y);
      sum_sq += d.dot(d);
    }
    const double rms = std::sqrt(sum_sq / static_cast<double>(corners.size()));
    if (rms > options.max_rms_px) continue;  // a mirrored order does not fit
    const Rigid3d world_from_cam = FromRvecTvec(rvec, tvec).Inverse();
    const double angle =
        AngleBetween(world_from_cam.rotation, hint_world_from_cam.rotation);
    // Among orderings that fit, the one nearest the hint; a clearly better
    // fit wins regardless.
    if (best && !(angle < best_angle && rms < 2.0 * best_rms) &&
        !(rms * 2.0 < best_rms)) {
      continue;
    }
    BoardPose pose;
    pose.world_from_cam = world_from_cam;
    pose.rms_px = rms;
    pose.median_px = ComputeErrorStats(errors).median;
    SetFormalSigmas(jacobian, sum_sq, corners.size(), rvec, tvec, &pose);
    best = pose;
    best_angle = angle;
    best_rms = rms;
  }
  return best;
}

BoardPoseReport EstimateBoardPoses(const std::function<cv::Mat(int)>& load_grey,
                                   const std::vector<double>& timestamps,
                                   const std::vector<Rigid3d>& hints,
                                   const Camera& camera,
                                   const CheckerboardSpec& spec,
                                   const BoardPoseOptions& options) {
  options.Check();
  if (timestamps.size() != hints.size()) {
    throw StageError(
        "EstimateBoardPoses: " + std::to_string(timestamps.size()) +
        " timestamps but " + std::to_string(hints.size()) + " hints");
  }
  const int n = static_cast<int>(timestamps.size());
  std::vector<std::optional<BoardPose>> found(n);
  tbb::parallel_for(0, n, [&](int i) {
    found[i] = EstimateBoardPose(load_grey(i), camera, spec, hints[i], options);
  });
  BoardPoseReport report;
  report.frames = n;
  std::vector<double> rms, rot, pos;
  for (int i = 0; i < n; ++i) {
    if (!found[i]) continue;
    report.poses.push_back({timestamps[i], found[i]->world_from_cam});
    rms.push_back(found[i]->rms_px);
    rot.push_back(found[i]->rotation_sigma_deg);
    pos.push_back(found[i]->position_sigma_m);
  }
  report.rms_px = ComputeErrorStats(rms);
  report.rotation_sigma_deg = ComputeErrorStats(rot);
  report.position_sigma_m = ComputeErrorStats(pos);
  return report;
}

void ExpressInAnchorFrame(const Rigid3d& anchor_world_from_cam,
                          std::vector<TimedPose>* poses) {
  if (poses->empty()) return;
  // anchor_from_board_world, the same for every frame.
  const Rigid3d change =
      anchor_world_from_cam * (*poses)[0].world_from_cam.Inverse();
  for (TimedPose& p : *poses) p.world_from_cam = change * p.world_from_cam;
}

}  // namespace monomap
