#include "monomap/eval/trajectory_metrics.h"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <string>

#include "monomap/util/angles.h"
#include "monomap/util/error.h"

namespace monomap {

namespace {

void CheckSorted(const std::vector<TimedPose>& poses, const char* what) {
  for (size_t i = 1; i < poses.size(); ++i) {
    if (!(poses[i].timestamp > poses[i - 1].timestamp)) {
      throw StageError(std::string("trajectory evaluation: ") + what +
                       " timestamps do not increase at pose " +
                       std::to_string(i));
    }
  }
}

}  // namespace

Alignment ParseAlignment(const std::string& name) {
  if (name == "none") return Alignment::kNone;
  if (name == "first") return Alignment::kFirstPose;
  if (name == "se3") return Alignment::kSE3;
  if (name == "sim3") return Alignment::kSim3;
  if (name == "sim3-poses") return Alignment::kSim3Poses;
  if (name == "se3-poses") return Alignment::kSE3Poses;
  throw OptionsError(
      "alignment: expected none, first, se3, sim3 or sim3-poses, got '" + name +
      "'");
}

std::vector<std::pair<size_t, size_t>> AssociateByTimestamp(
    const std::vector<TimedPose>& estimate,
    const std::vector<TimedPose>& groundtruth, double max_dt) {
  CheckOption(max_dt >= 0.0, "max_dt", "must be >= 0");
  CheckSorted(estimate, "estimated");
  CheckSorted(groundtruth, "ground-truth");
  std::vector<std::pair<size_t, size_t>> pairs;
  std::vector<bool> used(groundtruth.size(), false);
  for (size_t i = 0; i < estimate.size(); ++i) {
    const double t = estimate[i].timestamp;
    const auto it = std::lower_bound(
        groundtruth.begin(), groundtruth.end(), t,
        [](const TimedPose& p, double v) { return p.timestamp < v; });
    size_t best = groundtruth.size();
    double best_dt = max_dt;
    for (auto cand : {it, it == groundtruth.begin() ? it : it - 1}) {
      if (cand == groundtruth.end()) continue;
      const double dt = std::abs(cand->timestamp - t);
      if (dt <= best_dt) {
        best_dt = dt;
        best = cand - groundtruth.begin();
      }
    }
    if (best < groundtruth.size() && !used[best]) {
      used[best] = true;
      pairs.emplace_back(i, best);
    }
  }
  return pairs;
}

namespace {

// kSim3Poses / kSE3Poses: rotation = the chordal mean of R_gt R_est^T
// (projected onto SO(3)); with it fixed, scale (1 without `with_scale`) and
// translation minimise sum |s R p_est + t - p_gt|^2 in closed form.
Sim3d AlignPoses(const std::vector<TimedPose>& est,
                 const std::vector<TimedPose>& gt,
                 const std::vector<std::pair<size_t, size_t>>& pairs,
                 bool with_scale) {
  Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
  Eigen::Vector3d mean_est = Eigen::Vector3d::Zero();
  Eigen::Vector3d mean_gt = Eigen::Vector3d::Zero();
  for (const auto& [i, j] : pairs) {
    sum += (gt[j].world_from_cam.rotation *
            est[i].world_from_cam.rotation.inverse())
               .toRotationMatrix();
    mean_est += est[i].world_from_cam.translation;
    mean_gt += gt[j].world_from_cam.translation;
  }
  mean_est /= static_cast<double>(pairs.size());
  mean_gt /= static_cast<double>(pairs.size());
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(
      sum, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  d(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant();
  const Eigen::Matrix3d r = svd.matrixU() * d * svd.matrixV().transpose();
  double num = 0.0, den = 0.0;
  for (const auto& [i, j] : pairs) {
    const Eigen::Vector3d p =
        r * (est[i].world_from_cam.translation - mean_est);
    num += p.dot(gt[j].world_from_cam.translation - mean_gt);
    den += p.squaredNorm();
  }
  if (with_scale && (!(den > 0.0) || !(num > 0.0))) {
    throw StageError(
        "trajectory evaluation: estimated positions do not move, the scale "
        "of a sim3-poses alignment is undetermined");
  }
  Sim3d sim;
  sim.scale = with_scale ? num / den : 1.0;
  sim.rigid =
      Rigid3d(Eigen::Quaterniond(r), mean_gt - sim.scale * r * mean_est);
  return sim;
}

Sim3d AlignMatched(const std::vector<TimedPose>& est,
                   const std::vector<TimedPose>& gt,
                   const std::vector<std::pair<size_t, size_t>>& pairs,
                   Alignment alignment) {
  const size_t needed =
      (alignment == Alignment::kSE3 || alignment == Alignment::kSim3 ||
       alignment == Alignment::kSim3Poses || alignment == Alignment::kSE3Poses)
          ? 3
          : 2;
  if (pairs.size() < needed) {
    throw StageError(
        "trajectory evaluation: only " + std::to_string(pairs.size()) +
        " poses matched by timestamp, need " + std::to_string(needed));
  }
  Sim3d sim;
  switch (alignment) {
    case Alignment::kNone:
      return sim;
    case Alignment::kFirstPose:
      sim.rigid = gt[pairs[0].second].world_from_cam *
                  est[pairs[0].first].world_from_cam.Inverse();
      return sim;
    case Alignment::kSim3Poses:
    case Alignment::kSE3Poses:
      return AlignPoses(est, gt, pairs, alignment == Alignment::kSim3Poses);
    case Alignment::kSE3:
    case Alignment::kSim3:
      break;
  }
  Eigen::Matrix3Xd src(3, pairs.size()), dst(3, pairs.size());
  for (size_t k = 0; k < pairs.size(); ++k) {
    src.col(k) = est[pairs[k].first].world_from_cam.translation;
    dst.col(k) = gt[pairs[k].second].world_from_cam.translation;
  }
  // Umeyama leaves the rotation about the line undetermined for collinear
  // positions: refuse rather than report a meaningless rotation error.
  const Eigen::Matrix3Xd centered = src.colwise() - src.rowwise().mean();
  const Eigen::Vector3d sv =
      Eigen::JacobiSVD<Eigen::Matrix3Xd>(centered).singularValues();
  if (!(sv[0] > 0.0) || sv[1] < 1e-6 * sv[0]) {
    throw StageError(
        "trajectory evaluation: estimated positions are collinear or "
        "identical, SE3/Sim3 alignment is undetermined (use first-pose)");
  }
  const Eigen::Matrix4d m =
      Eigen::umeyama(src, dst, alignment == Alignment::kSim3);
  const Eigen::Matrix3d sr = m.topLeftCorner<3, 3>();
  sim.scale = std::cbrt(sr.determinant());
  sim.rigid =
      Rigid3d(Eigen::Quaterniond(sr / sim.scale), m.topRightCorner<3, 1>());
  return sim;
}

}  // namespace

Sim3d AlignTrajectories(const std::vector<TimedPose>& estimate,
                        const std::vector<TimedPose>& groundtruth,
                        Alignment alignment, double max_dt) {
  return AlignMatched(estimate, groundtruth,
                      AssociateByTimestamp(estimate, groundtruth, max_dt),
                      alignment);
}

TrajectoryErrors AbsoluteTrajectoryError(
    const std::vector<TimedPose>& estimate,
    const std::vector<TimedPose>& groundtruth, Alignment alignment,
    double max_dt) {
  const auto pairs = AssociateByTimestamp(estimate, groundtruth, max_dt);
  const Sim3d sim = AlignMatched(estimate, groundtruth, pairs, alignment);
  std::vector<double> trans, rot;
  trans.reserve(pairs.size());
  rot.reserve(pairs.size());
  for (const auto& [i, j] : pairs) {
    const Rigid3d& e = estimate[i].world_from_cam;
    const Rigid3d& g = groundtruth[j].world_from_cam;
    const Eigen::Vector3d p = sim.scale * (sim.rigid.rotation * e.translation) +
                              sim.rigid.translation;
    trans.push_back((p - g.translation).norm());
    rot.push_back(
        RadToDeg(AngleBetween(sim.rigid.rotation * e.rotation, g.rotation)));
  }
  TrajectoryErrors out;
  out.matched = pairs.size();
  out.translation_m = ComputeErrorStats(std::move(trans));
  out.rotation_deg = ComputeErrorStats(std::move(rot));
  out.scale = sim.scale;
  return out;
}

TrajectoryErrors RelativePoseError(const std::vector<TimedPose>& estimate,
                                   const std::vector<TimedPose>& groundtruth,
                                   int delta_frames, double max_dt) {
  CheckOption(delta_frames >= 1, "delta_frames", "must be >= 1");
  const auto pairs = AssociateByTimestamp(estimate, groundtruth, max_dt);
  const size_t needed = std::max<size_t>(2, delta_frames + 1);
  if (pairs.size() < needed) {
    throw StageError(
        "relative pose error: only " + std::to_string(pairs.size()) +
        " poses matched by timestamp, need " + std::to_string(needed) +
        " for delta " + std::to_string(delta_frames));
  }
  std::vector<double> trans, rot;
  for (size_t k = 0; k + delta_frames < pairs.size(); ++k) {
    const auto& a = pairs[k];
    const auto& b = pairs[k + delta_frames];
    const Rigid3d rel_est = estimate[a.first].world_from_cam.Inverse() *
                            estimate[b.first].world_from_cam;
    const Rigid3d rel_gt = groundtruth[a.second].world_from_cam.Inverse() *
                           groundtruth[b.second].world_from_cam;
    const Rigid3d err = rel_gt.Inverse() * rel_est;
    trans.push_back(err.translation.norm());
    rot.push_back(
        RadToDeg(AngleBetween(err.rotation, Eigen::Quaterniond::Identity())));
  }
  TrajectoryErrors out;
  out.matched = trans.size();
  out.translation_m = ComputeErrorStats(std::move(trans));
  out.rotation_deg = ComputeErrorStats(std::move(rot));
  return out;
}

}  // namespace monomap
