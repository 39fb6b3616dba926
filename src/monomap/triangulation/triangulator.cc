#include "monomap/triangulation/triangulator.h"

#include <ceres/jet.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "monomap/geometry/triangulation.h"
#include "monomap/triangulation/projection.h"
#include "monomap/util/angles.h"
#include "monomap/util/error.h"
#include "monomap/util/progress.h"
#include "monomap/util/stats.h"

namespace monomap {
namespace {

enum class Outcome : uint8_t {
  kAccepted,
  kShort,
  kFailed,
  kCheirality,
  kAngle,
  kReprojection
};

// Sum of squared pixel residuals and, if j_t_j/j_t_r are given, the normal
// equations of the 3-parameter problem. Returns +inf if the point is not in
// front of every camera, which the refinement treats as a rejected step.
double PointCost(const internal::Intrinsics& intrinsics,
                 const std::vector<Rigid3d>& cams,
                 const std::vector<Eigen::Vector2d>& observed,
                 const Eigen::Vector3d& x, Eigen::Matrix3d* j_t_j,
                 Eigen::Vector3d* j_t_r) {
  using Jet = ceres::Jet<double, 3>;
  double cost = 0.0;
  if (j_t_j != nullptr) {
    j_t_j->setZero();
    j_t_r->setZero();
  }
  const Eigen::Matrix<Jet, 3, 1> xj(Jet(x.x(), 0), Jet(x.y(), 1),
                                    Jet(x.z(), 2));
  for (size_t i = 0; i < cams.size(); ++i) {
    const Eigen::Matrix3d r = cams[i].RotationMatrix();
    const Eigen::Vector3d xc = r * x + cams[i].translation;
    if (!(xc.z() > 0.0)) return std::numeric_limits<double>::infinity();
    if (j_t_j == nullptr) {
      double px[2];
      internal::ProjectToImage(intrinsics, xc.data(), px);
      cost += (Eigen::Vector2d(px[0], px[1]) - observed[i]).squaredNorm();
      continue;
    }
    const Eigen::Matrix<Jet, 3, 1> xcj =
        r.cast<Jet>() * xj + cams[i].translation.cast<Jet>();
    Jet px[2];
    internal::ProjectToImage(intrinsics, xcj.data(), px);
    for (int k = 0; k < 2; ++k) {
      const double res = px[k].a - observed[i][k];
      cost += res * res;
      *j_t_j += px[k].v * px[k].v.transpose();
      *j_t_r += px[k].v * res;
    }
  }
  return cost;
}

// Levenberg-Marquardt on the point only (poses fixed): a 3x3 system per
// iteration, far cheaper than setting up a Ceres problem per track.
void RefinePointLm(const internal::Intrinsics& intrinsics,
                 const std::vector<Rigid3d>& cams,
                 const std::vector<Eigen::Vector2d>& observed,
                 const TriangulationOptions& options, Eigen::Vector3d* x) {
  const Eigen::Vector3d center0 = cams[0].Inverse().translation;
  double lambda = 1e-4;
  Eigen::Matrix3d jtj;
  Eigen::Vector3d jtr;
  double cost = PointCost(intrinsics, cams, observed, *x, &jtj, &jtr);
  if (!std::isfinite(cost)) return;
  for (int iter = 0; iter < options.max_refinement_iterations; ++iter) {
    Eigen::Matrix3d a = jtj;
    a.diagonal() *= 1.0 + lambda;
    const Eigen::Vector3d step = a.ldlt().solve(-jtr);
    if (!step.allFinite()) return;
    const Eigen::Vector3d candidate = *x + step;
    const double new_cost =
        PointCost(intrinsics, cams, observed, candidate, nullptr, nullptr);
    if (new_cost < cost) {
      *x = candidate;
      lambda = std::max(lambda * 0.1, 1e-10);
      if (step.norm() <
              options.refinement_tolerance * (*x - center0).norm() ||
          cost - new_cost < 1e-12 * cost) {
        return;
      }
      cost = PointCost(intrinsics, cams, observed, *x, &jtj, &jtr);
    } else {
      lambda *= 10.0;
      if (lambda > 1e8) return;  // no descent left: at the minimum
    }
  }
}

}  // namespace

void TriangulationOptions::Check() const {
  CheckOption(min_track_length >= 2, "min_track_length", "must be >= 2");
  CheckOption(max_reprojection_error_px > 0, "max_reprojection_error_px",
              "must be positive");
  CheckOption(max_observation_error_px >= max_reprojection_error_px,
              "max_observation_error_px",
              "must be >= max_reprojection_error_px");
  CheckOption(min_triangulation_angle_deg >= 0 &&
                  min_triangulation_angle_deg < 90,
              "min_triangulation_angle_deg", "must be in [0, 90)");
  CheckOption(min_depth_m > 0, "min_depth_m", "must be positive");
  CheckOption(max_depth_m > min_depth_m, "max_depth_m",
              "must be > min_depth_m");
  CheckOption(max_refinement_iterations >= 0, "max_refinement_iterations",
              "must be >= 0");
  CheckOption(refinement_tolerance > 0, "refinement_tolerance",
              "must be positive");
}

void RefinePoint(const Camera& camera,
                 const std::vector<Rigid3d>& cams_from_world,
                 const Track& track, const TriangulationOptions& options,
                 Eigen::Vector3d* x_in_world) {
  if (track.observations.empty()) return;
  std::vector<Rigid3d> cams;
  std::vector<Eigen::Vector2d> observed;
  for (const Observation& obs : track.observations) {
    cams.push_back(cams_from_world[obs.frame]);
    observed.push_back(obs.px);
  }
  RefinePointLm(internal::Intrinsics(camera), cams, observed, options,
                x_in_world);
}

PointStatistics EvaluatePoint(const Camera& camera,
                              const std::vector<Rigid3d>& cams_from_world,
                              const Track& track,
                              const Eigen::Vector3d& x_in_world) {
  PointStatistics s;
  s.min_depth_m = std::numeric_limits<double>::infinity();
  s.max_depth_m = -std::numeric_limits<double>::infinity();
  std::vector<Rigid3d> cams;
  cams.reserve(track.observations.size());
  double sum_error = 0.0;
  double sum_distance = 0.0;
  for (const Observation& obs : track.observations) {
    const Rigid3d& cam = cams_from_world[obs.frame];
    cams.push_back(cam);
    const Eigen::Vector3d xc = cam * x_in_world;
    s.min_depth_m = std::min(s.min_depth_m, xc.z());
    s.max_depth_m = std::max(s.max_depth_m, xc.z());
    sum_distance += xc.norm();
    const double error =
        xc.z() > 0 ? (camera.ImageFromCam(xc) - obs.px).norm()
                   : std::numeric_limits<double>::infinity();
    sum_error += error;
    s.max_error_px = std::max(s.max_error_px, error);
  }
  const double n = std::max<size_t>(1, track.observations.size());
  s.mean_error_px = sum_error / n;
  s.mean_distance_m = sum_distance / n;
  s.triangulation_angle_deg = RadToDeg(MaxTriangulationAngle(cams, x_in_world));
  std::vector<Eigen::Vector2d> observed;
  observed.reserve(track.observations.size());
  for (const Observation& obs : track.observations) observed.push_back(obs.px);
  Eigen::Matrix3d jtj;
  Eigen::Vector3d jtr;
  if (std::isfinite(PointCost(internal::Intrinsics(camera), cams, observed,
                              x_in_world, &jtj, &jtr))) {
    const Eigen::LDLT<Eigen::Matrix3d> ldlt(jtj);
    if (ldlt.info() == Eigen::Success && ldlt.isPositive() &&
        ldlt.vectorD().minCoeff() > 1e-12 * ldlt.vectorD().maxCoeff()) {
      s.covariance_m2_per_px2 = ldlt.solve(Eigen::Matrix3d::Identity());
    }
  }
  return s;
}

namespace {

void CheckTrackFrames(const std::vector<Track>& tracks, int num_frames) {
  for (const Track& track : tracks) {
    for (const Observation& obs : track.observations) {
      if (obs.frame < 0 || obs.frame >= num_frames) {
        throw InputError("track " + std::to_string(track.id) +
                         " observed in frame " + std::to_string(obs.frame) +
                         " which has no pose (" + std::to_string(num_frames) +
                         " poses)");
      }
    }
  }
}

// Buffers one thread reuses from track to track.
struct TrackScratch {
  std::vector<Rigid3d> cams;
  std::vector<Eigen::Vector2d> normalized, observed;
};

// Triangulates one track: linear estimate, cheirality, refinement, then
// the acceptance tests; *landmark is filled if accepted.
Outcome TriangulateTrack(const Camera& camera,
                         const internal::Intrinsics& intrinsics,
                         const std::vector<Rigid3d>& cams_from_world,
                         const Track& track,
                         const TriangulationOptions& options,
                         TrackScratch* scratch, Landmark* landmark) {
  const int n = static_cast<int>(track.observations.size());
  if (n < options.min_track_length) return Outcome::kShort;
  std::vector<Rigid3d>& cams = scratch->cams;
  cams.clear();
  scratch->normalized.clear();
  scratch->observed.clear();
  for (const Observation& obs : track.observations) {
    cams.push_back(cams_from_world[obs.frame]);
    scratch->normalized.push_back(camera.NormalizedFromImage(obs.px));
    scratch->observed.push_back(obs.px);
  }
  Eigen::Vector3d x;
  if (!TriangulateLinear(cams, scratch->normalized, &x)) {
    return Outcome::kFailed;
  }
  // Cheirality of the linear estimate first: refining a point behind the
  // cameras would only chase a mirrored solution.
  for (const Rigid3d& cam : cams) {
    if (DepthInCamera(cam, x) < options.min_depth_m) {
      return Outcome::kCheirality;
    }
  }
  if (options.nonlinear_refinement) {
    RefinePointLm(intrinsics, cams, scratch->observed, options, &x);
  }
  if (!x.allFinite()) return Outcome::kFailed;
  const PointStatistics s = EvaluatePoint(camera, cams_from_world, track, x);
  if (s.min_depth_m < options.min_depth_m ||
      s.max_depth_m > options.max_depth_m) {
    return Outcome::kCheirality;
  }
  if (s.triangulation_angle_deg < options.min_triangulation_angle_deg) {
    return Outcome::kAngle;
  }
  if (s.mean_error_px > options.max_reprojection_error_px ||
      s.max_error_px > options.max_observation_error_px) {
    return Outcome::kReprojection;
  }
  landmark->id = track.id;
  landmark->x_in_world = x;
  landmark->num_observations = n;
  landmark->mean_reprojection_error_px = s.mean_error_px;
  landmark->triangulation_angle_deg = s.triangulation_angle_deg;
  landmark->mean_depth_m = s.mean_distance_m;
  landmark->covariance_m2_per_px2 = s.covariance_m2_per_px2;
  return Outcome::kAccepted;
}

}  // namespace

TriangulationReport TriangulateTracks(const Camera& camera,
                                      const std::vector<Rigid3d>& world_from_cam,
                                      const std::vector<Track>& tracks,
                                      const TriangulationOptions& options,
                                      std::vector<Landmark>* landmarks) {
  options.Check();
  camera.Check();
  const Timer timer;
  CheckTrackFrames(tracks, static_cast<int>(world_from_cam.size()));
  std::vector<Rigid3d> cams_from_world(world_from_cam.size());
  for (size_t i = 0; i < world_from_cam.size(); ++i) {
    cams_from_world[i] = world_from_cam[i].Inverse();
  }
  const internal::Intrinsics intrinsics(camera);

  std::vector<Outcome> outcomes(tracks.size(), Outcome::kFailed);
  std::vector<Landmark> candidates(tracks.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, tracks.size(), 64),
                    [&](const tbb::blocked_range<size_t>& range) {
                      TrackScratch scratch;
                      for (size_t t = range.begin(); t != range.end(); ++t) {
                        outcomes[t] = TriangulateTrack(
                            camera, intrinsics, cams_from_world, tracks[t],
                            options, &scratch, &candidates[t]);
                      }
                    });

  TriangulationReport report;
  report.num_tracks = static_cast<int>(tracks.size());
  landmarks->clear();
  std::vector<double> errors;
  for (size_t t = 0; t < tracks.size(); ++t) {
    switch (outcomes[t]) {
      case Outcome::kAccepted:
        landmarks->push_back(candidates[t]);
        errors.push_back(candidates[t].mean_reprojection_error_px);
        break;
      case Outcome::kShort: ++report.rejected_short; break;
      case Outcome::kFailed: ++report.rejected_failed; break;
      case Outcome::kCheirality: ++report.rejected_cheirality; break;
      case Outcome::kAngle: ++report.rejected_angle; break;
      case Outcome::kReprojection: ++report.rejected_reprojection; break;
    }
  }
  report.num_points = static_cast<int>(landmarks->size());
  if (!errors.empty()) {
    double sum = 0.0;
    for (double e : errors) sum += e;
    report.mean_reprojection_error_px = sum / errors.size();
    report.median_reprojection_error_px = UpperMedian(std::move(errors));
  }
  report.seconds = timer.ElapsedSeconds();
  return report;
}

std::vector<Track> ObservationsWithinRadius(const std::vector<Track>& tracks,
                                            const Camera& camera,
                                            double max_radius_px,
                                            int64_t* dropped) {
  std::vector<Track> kept;
  kept.reserve(tracks.size());
  int64_t removed = 0;
  const double r2 = max_radius_px * max_radius_px;
  for (const Track& t : tracks) {
    Track k;
    k.id = t.id;
    for (const Observation& o : t.observations) {
      const double du = o.px.x() - camera.cx, dv = o.px.y() - camera.cy;
      if (du * du + dv * dv <= r2) {
        k.observations.push_back(o);
      } else {
        ++removed;
      }
    }
    if (!k.observations.empty()) kept.push_back(std::move(k));
  }
  if (dropped) *dropped = removed;
  return kept;
}

}  // namespace monomap
