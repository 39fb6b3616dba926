#include "monomap/texture/image_plane_homography.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <unordered_map>
#include <unordered_set>

#include "monomap/geometry/homography.h"
#include "monomap/camera/distorted_projector.h"
#include "monomap/util/error.h"
#include "monomap/util/progress.h"
#include "monomap/util/stats.h"

namespace monomap {
namespace {

// A plane feature seen in a frame: plane coordinates of its landmark and
// its undistorted observed pixel.
struct FeatureSighting {
  Eigen::Vector2d st;
  Eigen::Vector2d px;
  Eigen::Vector3d x_in_world;  // the landmark itself (off the plane a bit)
};

// The sightings whose landmark projects within max_parallax_px of where
// the pose-induced homography puts its plane projection: a landmark off
// the plane (a key on a keyboard, a point within the plane fit's band)
// is displaced by parallax that no homography of the plane explains, so
// it says nothing about the homography.
std::vector<FeatureSighting> OnPlaneSightings(
    const std::vector<FeatureSighting>& sightings, const Eigen::Matrix3d& k,
    const Rigid3d& cam_from_world, const Eigen::Matrix3d& pixel_from_plane,
    double max_parallax_px) {
  std::vector<FeatureSighting> kept;
  kept.reserve(sightings.size());
  for (const auto& f : sightings) {
    const Eigen::Vector3d x_in_cam = cam_from_world * f.x_in_world;
    const Eigen::Vector3d y = pixel_from_plane * f.st.homogeneous();
    if (x_in_cam.z() <= 0.0 || y.z() <= 0.0) continue;
    const Eigen::Vector2d landmark_px = (k * x_in_cam).hnormalized();
    if ((landmark_px - y.hnormalized()).norm() <= max_parallax_px) {
      kept.push_back(f);
    }
  }
  return kept;
}

ResidualStats Residuals(const Eigen::Matrix3d& h,
                        const std::vector<FeatureSighting>& sightings) {
  ResidualStats stats;
  if (sightings.empty()) return stats;
  std::vector<double> r;
  r.reserve(sightings.size());
  for (const auto& f : sightings) {
    const Eigen::Vector3d y = h * f.st.homogeneous();
    r.push_back(y.z() > 0 ? (y.hnormalized() - f.px).norm()
                          : std::numeric_limits<double>::infinity());
  }
  double sum = 0.0;
  for (double x : r) {
    sum += x;
    stats.max = std::max(stats.max, x);
  }
  stats.mean = sum / r.size();
  stats.median = Median(r);
  return stats;
}

// Samples of the polygon interior on a grid (plus its vertices), in plane
// coordinates.
std::vector<Eigen::Vector2d> PolygonSamples(const Polygon2d& polygon,
                                            int grid) {
  std::vector<Eigen::Vector2d> samples(polygon.begin(), polygon.end());
  Eigen::Vector2d lo, hi;
  PolygonBounds(polygon, &lo, &hi);
  for (int i = 0; i < grid; ++i) {
    for (int j = 0; j < grid; ++j) {
      const Eigen::Vector2d st(lo.x() + (hi.x() - lo.x()) * (i + 0.5) / grid,
                               lo.y() + (hi.y() - lo.y()) * (j + 0.5) / grid);
      if (PointInPolygon(polygon, st)) samples.push_back(st);
    }
  }
  return samples;
}

}  // namespace

void HomographyOptions::Check() const {
  CheckOption(visibility_grid >= 1, "homographies.visibility_grid",
              "must be >= 1");
  CheckOption(min_visible_fraction >= 0.0 && min_visible_fraction <= 1.0,
              "homographies.min_visible_fraction", "must be in [0, 1]");
  CheckOption(min_depth_m > 0.0, "homographies.min_depth_m", "must be > 0");
  CheckOption(refine_threshold_px >= 0.0, "homographies.refine_threshold_px",
              "must be >= 0");
  CheckOption(min_features_to_refine >= 4,
              "homographies.min_features_to_refine",
              "must be >= 4 (a homography needs 4 points)");
  CheckOption(ransac_threshold_px > 0.0, "homographies.ransac_threshold_px",
              "must be > 0");
  CheckOption(max_feature_parallax_px > 0.0,
              "homographies.max_feature_parallax_px", "must be > 0");
  CheckOption(max_corner_shift_px > 0.0, "homographies.max_corner_shift_px",
              "must be > 0");
}

Eigen::Vector2d UndistortedPixel(const Camera& camera,
                                 const Eigen::Vector2d& raw_px) {
  return camera.PinholeFromNormalized(camera.NormalizedFromImage(raw_px));
}

double HomographyPixelsPerMeter(const Eigen::Matrix3d& h,
                                const Eigen::Vector2d& st) {
  const Eigen::Vector3d y = h * st.homogeneous();
  if (std::abs(y.z()) < 1e-12) return 0.0;
  const Eigen::Vector2d p = y.head<2>() / y.z();
  // d(p)/d(st) = (H[0:2, 0:2] - p * H[2, 0:2]) / w.
  const Eigen::Matrix2d j =
      (h.topLeftCorner<2, 2>() - p * h.block<1, 2>(2, 0)) / y.z();
  return std::sqrt(std::abs(j.determinant()));
}

namespace {

// Feature sightings per (frame, plane), at frame * num_planes + plane; a
// plane's features in id order (deterministic).
std::vector<std::vector<FeatureSighting>> SightingsByFramePlane(
    const Camera& camera, int num_frames,
    const std::vector<PlaneSegment>& segments,
    const std::vector<Landmark>& landmarks, const std::vector<Track>& tracks) {
  const int num_planes = static_cast<int>(segments.size());
  std::unordered_map<FeatureId, const Track*> track_by_id;
  for (const auto& t : tracks) track_by_id[t.id] = &t;
  std::unordered_map<FeatureId, const Landmark*> landmark_by_id;
  for (const auto& l : landmarks) landmark_by_id[l.id] = &l;
  std::vector<std::vector<FeatureSighting>> sightings(
      static_cast<size_t>(num_frames) * num_planes);
  for (int p = 0; p < num_planes; ++p) {
    const PlaneSegment& seg = segments[p];
    std::unordered_set<FeatureId> ids(seg.inlier_ids.begin(),
                                      seg.inlier_ids.end());
    for (const auto& l : landmarks) {
      if (l.plane_id == seg.id) ids.insert(l.id);
    }
    std::vector<FeatureId> sorted(ids.begin(), ids.end());
    std::sort(sorted.begin(), sorted.end());  // deterministic order
    for (FeatureId id : sorted) {
      const auto lit = landmark_by_id.find(id);
      const auto tit = track_by_id.find(id);
      if (lit == landmark_by_id.end() || tit == track_by_id.end()) continue;
      const Eigen::Vector2d st =
          seg.frame.ToPlane(seg.plane.Project(lit->second->x_in_world));
      for (const Observation& o : tit->second->observations) {
        if (o.frame < 0 || o.frame >= num_frames) continue;
        sightings[static_cast<size_t>(o.frame) * num_planes + p].push_back(
            {st, UndistortedPixel(camera, o.px), lit->second->x_in_world});
      }
    }
  }
  return sightings;
}

// What every (frame, plane) pair shares.
struct HomographyContext {
  const Camera& camera;
  const DistortedProjector& projector;
  const Eigen::Matrix3d k;
  const HomographyOptions& options;
};

// Samples of the plane (plane coordinates) that project into the image.
int VisibleSamples(const HomographyContext& ctx, const Rigid3d& cam_from_world,
                   const PlaneFrame& frame,
                   const std::vector<Eigen::Vector2d>& samples) {
  int visible = 0;
  for (const auto& st : samples) {
    Eigen::Vector2d px;
    if (ctx.projector.Project(cam_from_world * frame.ToWorld(st), &px) &&
        ctx.camera.InImage(px)) {
      ++visible;
    }
  }
  return visible;
}

// pixel_from_plane corrected by a homography from its predicted to the
// observed pixels (both in pixels, so the estimate is well conditioned),
// signed so that the plane centre is in front. False if RANSAC found none.
bool CorrectedHomography(const Eigen::Matrix3d& pixel_from_plane,
                         const std::vector<FeatureSighting>& feats,
                         const Eigen::Vector2d& centre,
                         const HomographyOptions& options, Eigen::Matrix3d* h) {
  std::vector<cv::Point2f> predicted, observed;
  for (const auto& s : feats) {
    const Eigen::Vector3d y = pixel_from_plane * s.st.homogeneous();
    if (y.z() <= 0) continue;
    const Eigen::Vector2d q = y.hnormalized();
    predicted.emplace_back(static_cast<float>(q.x()),
                           static_cast<float>(q.y()));
    observed.emplace_back(static_cast<float>(s.px.x()),
                          static_cast<float>(s.px.y()));
  }
  cv::Mat c_cv;
  if (static_cast<int>(predicted.size()) >= options.min_features_to_refine) {
    c_cv = cv::findHomography(predicted, observed, cv::RANSAC,
                              options.ransac_threshold_px);
  }
  if (c_cv.empty()) return false;
  Eigen::Matrix3d c;
  cv::cv2eigen(c_cv, c);
  *h = c * pixel_from_plane;
  if ((*h * centre.homogeneous()).z() < 0) *h = -*h;
  return true;
}

// Whether h keeps every imaged polygon corner in front of the camera and
// within max_shift_px of where pixel_from_plane puts it.
bool CornersStay(const Eigen::Matrix3d& pixel_from_plane,
                 const Eigen::Matrix3d& h, const Polygon2d& polygon,
                 double max_shift_px) {
  for (const auto& v : polygon) {
    const Eigen::Vector3d y0 = pixel_from_plane * v.homogeneous();
    const Eigen::Vector3d y1 = h * v.homogeneous();
    if (y0.z() <= 0) continue;  // behind the camera: not imaged
    if (y1.z() <= 0 ||
        (y1.hnormalized() - y0.hnormalized()).norm() > max_shift_px) {
      return false;
    }
  }
  return true;
}

// Replaces hp's homography by the feature-corrected one if that keeps the
// corners and lowers the median residual.
void RefineHomography(const std::vector<FeatureSighting>& feats,
                      const PlaneSegment& seg, const Eigen::Vector2d& centre,
                      const HomographyOptions& options,
                      ImagePlaneHomography* hp) {
  Eigen::Matrix3d h;
  if (!CorrectedHomography(hp->pixel_from_plane, feats, centre, options, &h) ||
      !CornersStay(hp->pixel_from_plane, h, seg.polygon,
                   options.max_corner_shift_px)) {
    return;
  }
  const ResidualStats after = Residuals(h, feats);
  if (after.median < hp->before.median) {
    hp->pixel_from_plane = h;
    hp->after = after;
    hp->refined = true;
  }
}

// The homography of plane seg in frame f, refined if its features disagree
// (*attempted tells whether a refinement was tried). False if too little
// of the plane is visible.
bool FramePlaneHomography(const HomographyContext& ctx, int f,
                          const Rigid3d& cam_from_world,
                          const PlaneSegment& seg,
                          const std::vector<Eigen::Vector2d>& samples,
                          const Eigen::Vector2d& centre,
                          const std::vector<FeatureSighting>& sightings,
                          ImagePlaneHomography* hp, bool* attempted) {
  const HomographyOptions& options = ctx.options;
  const int visible = VisibleSamples(ctx, cam_from_world, seg.frame, samples);
  const double fraction = static_cast<double>(visible) / samples.size();
  if (visible == 0 || fraction < options.min_visible_fraction) return false;
  hp->frame = f;
  hp->plane_id = seg.id;
  hp->visible_fraction = fraction;
  hp->pixel_from_plane =
      ctx.k * NormalizedImageFromPlane(cam_from_world, seg.frame);
  const std::vector<FeatureSighting> feats =
      OnPlaneSightings(sightings, ctx.k, cam_from_world, hp->pixel_from_plane,
                       options.max_feature_parallax_px);
  hp->num_features = static_cast<int>(feats.size());
  hp->before = Residuals(hp->pixel_from_plane, feats);
  hp->after = hp->before;
  *attempted = options.refine &&
               hp->num_features >= options.min_features_to_refine &&
               hp->before.median > options.refine_threshold_px;
  if (*attempted) RefineHomography(feats, seg, centre, options, hp);
  hp->residual_before_px = hp->before.median;
  hp->residual_after_px = hp->after.median;
  hp->pixels_per_meter = HomographyPixelsPerMeter(hp->pixel_from_plane, centre);
  return true;
}

// Concatenates the frames' homographies and counts them into the report.
void CollectHomographies(
    const std::vector<std::vector<ImagePlaneHomography>>& per_frame,
    const std::vector<int>& attempted,
    std::vector<ImagePlaneHomography>* homographies, HomographyReport* report) {
  std::vector<double> before, after;
  for (size_t f = 0; f < per_frame.size(); ++f) {
    for (const auto& hp : per_frame[f]) {
      if (hp.num_features > 0) {
        ++report->num_checked;
        before.push_back(hp.residual_before_px);
        after.push_back(hp.residual_after_px);
      }
      if (hp.refined) ++report->num_refined;
      homographies->push_back(hp);
    }
    report->num_refinement_rejected += attempted[f];
  }
  report->num_refinement_rejected -= report->num_refined;
  report->num_homographies = static_cast<int>(homographies->size());
  report->median_residual_before_px = Median(before);
  report->median_residual_after_px = Median(after);
}

}  // namespace

HomographyReport ComputeImagePlaneHomographies(
    const Camera& camera, const std::vector<Rigid3d>& world_from_cam,
    const std::vector<PlaneSegment>& segments,
    const std::vector<Landmark>& landmarks, const std::vector<Track>& tracks,
    const HomographyOptions& options,
    std::vector<ImagePlaneHomography>* homographies) {
  options.Check();
  camera.Check();
  Timer timer;
  HomographyReport report;
  homographies->clear();
  const int num_frames = static_cast<int>(world_from_cam.size());
  const int num_planes = static_cast<int>(segments.size());
  if (num_frames == 0 || num_planes == 0) {
    report.seconds = timer.ElapsedSeconds();
    return report;
  }
  const std::vector<std::vector<FeatureSighting>> sightings =
      SightingsByFramePlane(camera, num_frames, segments, landmarks, tracks);
  std::vector<std::vector<Eigen::Vector2d>> samples(num_planes);
  std::vector<Eigen::Vector2d> centres(num_planes);
  for (int p = 0; p < num_planes; ++p) {
    // Visibility and resolution are judged over what the plane's inliers
    // support (landmark_polygon, where the polygon reaches further over
    // loose points or grown cells): the views chosen for the texture and
    // its resolution serve the part that localization renders.
    const PlaneSegment& seg = segments[p];
    const Polygon2d& region =
        seg.landmark_polygon.size() >= 3 ? seg.landmark_polygon : seg.polygon;
    if (seg.polygon.size() < 3 || region.size() < 3) continue;
    samples[p] = PolygonSamples(region, options.visibility_grid);
    Eigen::Vector2d lo, hi;
    PolygonBounds(region, &lo, &hi);
    centres[p] = 0.5 * (lo + hi);
  }

  const DistortedProjector projector(camera, options.min_depth_m);
  const HomographyContext ctx{camera, projector, camera.K(), options};
  std::vector<std::vector<ImagePlaneHomography>> per_frame(num_frames);
  std::vector<int> attempted(num_frames, 0);
  tbb::parallel_for(0, num_frames, [&](int f) {
    const Rigid3d cam_from_world = world_from_cam[f].Inverse();
    for (int p = 0; p < num_planes; ++p) {
      if (samples[p].empty()) continue;
      ImagePlaneHomography hp;
      bool tried = false;
      if (FramePlaneHomography(
              ctx, f, cam_from_world, segments[p], samples[p], centres[p],
              sightings[static_cast<size_t>(f) * num_planes + p], &hp,
              &tried)) {
        attempted[f] += tried;
        per_frame[f].push_back(hp);
      }
    }
  });
  CollectHomographies(per_frame, attempted, homographies, &report);
  report.seconds = timer.ElapsedSeconds();
  return report;
}

}  // namespace monomap
