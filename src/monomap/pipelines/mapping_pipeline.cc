#include "monomap/pipelines/mapping_pipeline.h"

#include <algorithm>
#include <fstream>
#include <mutex>
#include <opencv2/imgproc.hpp>
#include <unordered_map>

#include "monomap/io/feature_table.h"
#include "monomap/io/map_format.h"
#include "monomap/util/error.h"
#include "monomap/util/file.h"
#include "monomap/util/progress.h"

namespace monomap {

void MappingOptions::Check() const {
  tracking.Check();
  triangulation.Check();
  bundle_adjustment.Check();
  planes.Check();
  see_through.Check();
  growth.Check();
  hypotheses.Check();
  homographies.Check();
  mosaic.Check();
  point_trust.Check();
  inlier_refinement.Check();
  keyframes.Check();
  CheckOption(first_pass_error_factor >= 1.0, "mapping.first_pass_error_factor",
              "must be >= 1");
  CheckOption(max_observation_radius_px >= 0.0,
              "mapping.max_observation_radius_px", "must be >= 0");
}

namespace {

// Keeps a small colour thumbnail of every kInterval-th frame while tracking
// decodes it, so landmark colours need no second pass over the images. The
// other frames are decoded grey only: for JPEG that is 1.4 ms instead of
// 3.7 ms (no chroma upsampling and colour conversion; the grey values are
// the same), and a point looks the same a frame or two away.
class ThumbnailCache {
 public:
  static constexpr int kScale = 4;
  static constexpr int kInterval = 4;
  explicit ThumbnailCache(size_t frames) : thumbs_(frames) {}
  static bool Wanted(int frame) { return frame % kInterval == 0; }
  void Store(int frame, const cv::Mat& image) {
    cv::Mat small;
    cv::resize(image, small, cv::Size(), 1.0 / kScale, 1.0 / kScale,
               cv::INTER_AREA);
    if (small.channels() == 1) cv::cvtColor(small, small, cv::COLOR_GRAY2BGR);
    thumbs_[frame] = small;
  }
  // Colour of a track: at the observation nearest its middle whose frame
  // has a thumbnail; a short track between thumbnails takes its middle
  // pixel from the nearest thumbnail frame.
  Eigen::Vector3f TrackColor(const Track& track) const {
    const auto& obs = track.observations;
    if (obs.empty()) return Eigen::Vector3f::Zero();
    const int mid = static_cast<int>(obs.size()) / 2;
    int best = -1;
    for (int k = 0; k < static_cast<int>(obs.size()); ++k) {
      if (Has(obs[k].frame) &&
          (best < 0 || std::abs(k - mid) < std::abs(best - mid))) {
        best = k;
      }
    }
    if (best >= 0) return ColorAt(obs[best].frame, obs[best].px);
    const int f = obs[mid].frame;
    const int nearest = (f + kInterval / 2) / kInterval * kInterval;
    return ColorAt(Has(nearest) ? nearest : f / kInterval * kInterval,
                   obs[mid].px);
  }

 private:
  bool Has(int frame) const {
    return frame >= 0 && frame < static_cast<int>(thumbs_.size()) &&
           !thumbs_[frame].empty();
  }
  Eigen::Vector3f ColorAt(int frame, const Eigen::Vector2d& px) const {
    if (!Has(frame)) return Eigen::Vector3f::Zero();
    const cv::Mat& t = thumbs_[frame];
    const int c =
        std::clamp(static_cast<int>((px.x() + 0.5) / kScale), 0, t.cols - 1);
    const int r =
        std::clamp(static_cast<int>((px.y() + 0.5) / kScale), 0, t.rows - 1);
    const cv::Vec3b bgr = t.at<cv::Vec3b>(r, c);
    return Eigen::Vector3f(bgr[2], bgr[1], bgr[0]);
  }

  std::vector<cv::Mat> thumbs_;
};

// Stage 1: tracking (decoding overlaps tracking inside TrackFeatures);
// keeps colour thumbnails for the landmark colours.
void TrackStage(const Dataset& dataset, const MappingOptions& options,
                ThumbnailCache* thumbs, MappingResult* result) {
  const int num_frames = static_cast<int>(dataset.frames.size());
  Timer timer;
  ProgressBar progress("tracking", num_frames, options.show_progress);
  auto load = [&](int frame) {
    cv::Mat grey;
    if (ThumbnailCache::Wanted(frame)) {
      const cv::Mat color = dataset.LoadImage(frame, /*color=*/true);
      thumbs->Store(frame, color);
      cv::cvtColor(color, grey, cv::COLOR_BGR2GRAY);
    } else {
      grey = dataset.LoadImage(frame, /*color=*/false);
    }
    progress.Advance();
    return grey;
  };
  result->report.tracking =
      TrackFeatures(load, num_frames, options.tracking, &result->tracks);
  result->report.timings.push_back({"tracking", timer.ElapsedSeconds()});
  if (result->tracks.empty()) {
    throw StageError("tracking found no features in " + dataset.root.string());
  }
}

// Stage 2: triangulation against the odometry poses, bundle adjustment and
// triangulation again against the adjusted poses. Returns world_from_cam
// per frame; *camera gets the lens bundle adjustment settled on (the given
// one, or its refined distortion or intrinsics).
std::vector<Rigid3d> GeometryStage(const Dataset& dataset,
                                   const MappingOptions& options,
                                   const std::vector<Track>& tracks,
                                   Camera* camera, MappingResult* result) {
  MappingReport& report = result->report;
  Timer timer;
  std::vector<Rigid3d> world_from_cam;
  world_from_cam.reserve(dataset.frames.size());
  for (const auto& f : dataset.frames) {
    world_from_cam.push_back(f.odometry_world_from_cam);
  }
  result->odometry_world_from_cam = world_from_cam;
  std::vector<Landmark>& landmarks = result->map.landmarks;
  // With drifting odometry poses a strict reprojection test would reject
  // good tracks, so the first pass is loose: bundle adjustment (robust
  // loss) then corrects the poses, and every track is triangulated again
  // against the corrected poses with the strict thresholds.
  TriangulationOptions loose = options.triangulation;
  if (options.bundle_adjustment.enabled) {
    loose.max_reprojection_error_px *= options.first_pass_error_factor;
    loose.max_observation_error_px *= options.first_pass_error_factor;
  }
  report.triangulation =
      TriangulateTracks(*camera, world_from_cam, tracks, loose, &landmarks);
  report.timings.push_back({"triangulation", timer.ElapsedSeconds()});
  if (landmarks.empty()) {
    throw StageError(
        "no track could be triangulated (too little motion or "
        "too few features?)");
  }
  if (!options.bundle_adjustment.enabled) return world_from_cam;
  timer.Restart();
  BundleAdjustmentOptions ba = options.bundle_adjustment;
  // The loose first pass carries outliers: the joint solve sees them
  // through the robust loss; dropping uses the loose threshold too.
  ba.max_reprojection_error_px = loose.max_reprojection_error_px;
  // A wheeled base (odometry2d.txt with its mount) stays on the floor.
  ba.planar_base.base_from_cam = dataset.base_from_cam;
  report.bundle_adjustment = BundleAdjustKeyframes(
      *camera, tracks, ba, options.keyframes, &world_from_cam, &landmarks);
  *camera = report.bundle_adjustment.camera;
  report.timings.push_back({"bundle_adjustment", timer.ElapsedSeconds()});
  timer.Restart();
  report.retriangulation = TriangulateTracks(*camera, world_from_cam, tracks,
                                             options.triangulation, &landmarks);
  report.timings.push_back({"retriangulation", timer.ElapsedSeconds()});
  return world_from_cam;
}

// Landmark colours from a frame near the middle of each track.
void ColorLandmarks(const ThumbnailCache& thumbs,
                    const std::vector<Track>& tracks,
                    std::vector<Landmark>* landmarks) {
  std::unordered_map<FeatureId, const Track*> track_by_id;
  for (const auto& t : tracks) track_by_id[t.id] = &t;
  for (auto& l : *landmarks) {
    const auto it = track_by_id.find(l.id);
    if (it == track_by_id.end()) continue;
    l.color = thumbs.TrackColor(*it->second);
  }
}

// The landmarks of segments from `first` on (confirmed plane hypotheses)
// become their inliers.
void AssignInliers(size_t first, const std::vector<PlaneSegment>& segments,
                   std::vector<Landmark>* landmarks) {
  std::unordered_map<FeatureId, int> plane_of;
  for (size_t i = first; i < segments.size(); ++i) {
    for (FeatureId id : segments[i].inlier_ids) plane_of[id] = segments[i].id;
  }
  for (Landmark& l : *landmarks) {
    const auto it = plane_of.find(l.id);
    if (it != plane_of.end()) l.plane_id = it->second;
  }
}

// The fitting report describes the map's planes and outliers: the segments
// left after fitting and the see-through check, then also the confirmed
// hypotheses' (from `first` on).
void CountPlanes(size_t first, const std::vector<PlaneSegment>& segments,
                 const std::vector<Landmark>& landmarks,
                 PlaneFittingReport* planes) {
  planes->inliers_per_plane.clear();
  for (const PlaneSegment& seg : segments) {
    planes->inliers_per_plane.push_back(
        static_cast<int>(seg.inlier_ids.size()));
  }
  planes->from_hypotheses = static_cast<int>(segments.size() - first);
  planes->num_planes = static_cast<int>(segments.size());
  planes->num_outliers = static_cast<int>(
      std::count_if(landmarks.begin(), landmarks.end(),
                    [](const Landmark& l) { return l.plane_id < 0; }));
}

// Stages 3 to 5: planes, image-to-plane homographies and texture mosaics.
void SurfaceStages(const Dataset& dataset, const MappingOptions& options,
                   const Camera& camera,
                   const std::vector<Rigid3d>& world_from_cam,
                   const std::vector<Track>& tracks, MappingResult* result) {
  MappingReport& report = result->report;
  std::vector<Landmark>& landmarks = result->map.landmarks;
  Timer timer;
  std::vector<Eigen::Vector3d> centers;
  for (const auto& p : world_from_cam) centers.push_back(p.translation);
  report.planes =
      FitPlanes(options.planes, &landmarks, &result->segments, &centers);
  report.see_through = DropSeeThroughSegments(
      options.see_through, options.planes, world_from_cam, tracks, &landmarks,
      &result->segments);
  CountPlanes(result->segments.size(), result->segments, landmarks,
              &report.planes);
  report.timings.push_back({"planes", timer.ElapsedSeconds()});
  timer.Restart();
  auto load_grey = [&](int frame) { return dataset.LoadImage(frame, false); };
  std::vector<PlaneSegment> hypotheses;
  if (options.growth.enabled && options.hypotheses.enabled) {
    hypotheses = ProposePlaneHypotheses(options.hypotheses, options.planes,
                                        landmarks, result->segments, centers);
  }
  const size_t fitted = result->segments.size();
  report.growth = GrowPlanePolygons(options.growth, camera, world_from_cam,
                                    landmarks, tracks, load_grey,
                                    &result->segments, hypotheses);
  AssignInliers(fitted, result->segments, &landmarks);
  CountPlanes(fitted, result->segments, landmarks, &report.planes);
  report.timings.push_back({"plane_growth", timer.ElapsedSeconds()});
  auto load_image = [&](int frame) { return dataset.LoadImage(frame, true); };
  timer.Restart();
  std::vector<ImagePlaneHomography> homographies;
  report.homographies = ComputeImagePlaneHomographies(
      camera, world_from_cam, result->segments, landmarks, tracks,
      options.homographies, &homographies);
  report.timings.push_back({"homographies", timer.ElapsedSeconds()});
  timer.Restart();
  report.mosaic = BuildTexturedPlanes(
      camera, world_from_cam, result->segments, landmarks, tracks, homographies,
      load_image, options.mosaic, &result->map.planes);
  report.timings.push_back({"mosaic", timer.ElapsedSeconds()});
}

}  // namespace

bool SameCalibration(const Camera& a, const Camera& b) {
  return a.model == b.model && a.width == b.width && a.height == b.height &&
         a.fx == b.fx && a.fy == b.fy && a.cx == b.cx && a.cy == b.cy &&
         a.distortion == b.distortion;
}

MappingResult BuildMap(const Dataset& dataset, const MappingOptions& options) {
  options.Check();
  Timer total;
  MappingResult result;
  const int num_frames = static_cast<int>(dataset.frames.size());
  result.report.num_frames = num_frames;
  if (num_frames < 2) {
    throw StageError("need at least 2 frames to build a map, got " +
                     std::to_string(num_frames));
  }
  // The dataset's calibration; bundle adjustment may refine it (distortion,
  // or the intrinsics), and every stage after it (and the map) uses the
  // refined lens.
  Camera camera = dataset.camera;
  camera.Check();
  ThumbnailCache thumbs(num_frames);
  TrackStage(dataset, options, &thumbs, &result);
  // The geometry sees only the observations where the lens is trusted.
  std::vector<Track> inner_tracks;
  const std::vector<Track>* tracks = &result.tracks;
  if (options.max_observation_radius_px > 0.0) {
    inner_tracks = ObservationsWithinRadius(
        result.tracks, camera, options.max_observation_radius_px,
        &result.report.observations_beyond_radius);
    tracks = &inner_tracks;
  }
  const std::vector<Rigid3d> world_from_cam =
      GeometryStage(dataset, options, *tracks, &camera, &result);
  ColorLandmarks(thumbs, result.tracks, &result.map.landmarks);
  result.map.camera = camera;
  if (!SameCalibration(camera, dataset.camera)) {
    result.map.given_camera = dataset.camera;
  }
  result.map.trajectory.reserve(num_frames);
  for (int i = 0; i < num_frames; ++i) {
    result.map.trajectory.push_back(
        {dataset.frames[i].timestamp, world_from_cam[i]});
  }
  if (!options.points_only) {
    SurfaceStages(dataset, options, camera, world_from_cam, *tracks, &result);
  }
  // The map exports only the points it trusts; planes and textures above
  // were fitted from all of them.
  result.report.point_trust =
      FilterTrustedPoints(options.point_trust, &result.map.landmarks);
  Timer refinement;
  result.report.inlier_refinement = RefineInliersOnPlanes(
      options.inlier_refinement, result.segments, &result.map.landmarks);
  result.report.timings.push_back(
      {"inlier_refinement", refinement.ElapsedSeconds()});
  result.report.total_seconds = total.ElapsedSeconds();
  return result;
}

namespace {

nlohmann::json LensJson(const std::array<double, kLensSize>& v) {
  return {{"fx", v[kLensFx]}, {"fy", v[kLensFy]}, {"cx", v[kLensCx]},
          {"cy", v[kLensCy]}, {"k1", v[kLensK1]}, {"k2", v[kLensK2]},
          {"k3", v[kLensK3]}};
}

// The trials on each half of the frames (check_halves) and, per group, how
// far apart they are in combined sigmas (-1: not compared).
nlohmann::json HalvesJson(const IntrinsicsRefinementReport& r) {
  if (!r.halves_checked) return nullptr;
  return {{"first",
           {{"candidate", LensJson(r.halves_candidate[0])},
            {"posterior_std", LensJson(r.halves_std[0])}}},
          {"second",
           {{"candidate", LensJson(r.halves_candidate[1])},
            {"posterior_std", LensJson(r.halves_std[1])}}},
          {"sigmas_apart",
           {{"focal", r.halves_sigmas[kGroupFocal]},
            {"principal_point", r.halves_sigmas[kGroupPrincipalPoint]},
            {"radial", r.halves_sigmas[kGroupRadial]},
            {"k3", r.halves_sigmas[kGroupK3]}}}};
}

// Lens self-calibration: refined or not and why, before and after, prior
// and marginal standard deviations.
nlohmann::json IntrinsicsJson(const IntrinsicsRefinementReport& r) {
  if (!r.attempted) return {{"attempted", false}};
  return {{"attempted", true},
          {"refined", r.refined()},
          {"focal_refined", r.group_refined[kGroupFocal]},
          {"principal_point_refined", r.group_refined[kGroupPrincipalPoint]},
          {"radial_refined", r.group_refined[kGroupRadial]},
          {"k3_refined", r.group_refined[kGroupK3]},
          {"reason", r.reason},
          {"before", LensJson(LensParameters(r.before))},
          {"after", LensJson(LensParameters(r.after))},
          {"candidate", LensJson(r.candidate)},
          {"prior_std", LensJson(r.prior_std)},
          {"posterior_std", LensJson(r.posterior_std)},
          {"halves", HalvesJson(r)},
          {"covariance_seconds", r.covariance_seconds}};
}

nlohmann::json TrackingJson(const TrackingReport& tracking) {
  return {{"tracks", tracking.tracks_returned},
          {"tracks_created", tracking.tracks_created},
          {"mean_track_length", tracking.mean_track_length},
          {"mean_features_per_frame", tracking.mean_features_per_frame},
          {"affine_refined", tracking.refined},
          {"reference_patches_renewed", tracking.reanchored},
          {"split_after_failed_alignment", tracking.split},
          {"image_noise_sigma", tracking.noise_sigma},
          {"seconds", tracking.seconds}};
}

nlohmann::json BundleAdjustmentJson(const BundleAdjustmentReport& ba) {
  return {{"termination", ba.termination},
          {"poses", ba.num_poses},
          {"residuals", ba.num_residuals},
          {"span_priors", ba.num_span_priors},
          {"planar_priors", ba.num_planar_priors},
          {"points_joint", ba.num_points_joint},
          {"outlier_observations", ba.num_outlier_observations},
          {"outlier_points", ba.num_outlier_points},
          {"initial_rms_reprojection_error_px", ba.initial_rms_error_px},
          {"final_rms_reprojection_error_px", ba.final_rms_error_px},
          {"initial_median_reprojection_error_px", ba.initial_median_error_px},
          {"final_median_reprojection_error_px", ba.final_median_error_px},
          {"iterations", ba.iterations},
          {"covisibility", ba.covisibility},
          {"keyframe_thinning", ba.keyframe_thinning},
          {"distortion", ba.distortion},
          {"linear_solver", ba.linear_solver},
          {"points_dropped", ba.num_dropped},
          {"mean_pose_change_m", ba.mean_pose_change_m},
          {"mean_pose_change_deg", ba.mean_pose_change_deg},
          {"intrinsics", IntrinsicsJson(ba.intrinsics)}};
}

nlohmann::json PlanesJson(const PlaneFittingReport& planes) {
  nlohmann::json j = {{"planes", planes.num_planes},
                      {"from_hypotheses", planes.from_hypotheses},
                      {"outliers", planes.num_outliers},
                      {"absorbed_outliers", planes.absorbed},
                      {"inliers_per_plane", planes.inliers_per_plane}};
  // Segments merged into one plane (ids as fitted); empty when merging is off.
  j["merges"] = nlohmann::json::array();
  for (const auto& m : planes.merges) {
    j["merges"].push_back({{"kept_id", m.kept_id},
                           {"merged_id", m.merged_id},
                           {"angle_deg", m.angle_deg},
                           {"offset_m", m.offset_m},
                           {"offset_thresholds", m.offset_thresholds}});
  }
  // Segments whose normal was snapped to a direction of the scene (ids as
  // fitted).
  j["directions"] = planes.num_directions;
  j["snaps"] = nlohmann::json::array();
  for (const auto& sn : planes.snaps) {
    j["snaps"].push_back({{"segment_id", sn.segment_id},
                          {"kind", sn.kind},
                          {"angle_deg", sn.angle_deg},
                          {"kept_fraction", sn.kept_fraction}});
  }
  return j;
}

// Per fitted segment, the landmarks seen through it; the segments dropped
// for it (ids as fitted).
nlohmann::json SeeThroughJson(const SeeThroughReport& r) {
  nlohmann::json j = {{"seen_through", r.seen_through},
                      {"dropped", nlohmann::json::array()}};
  for (const auto& d : r.dropped) {
    j["dropped"].push_back({{"segment_id", d.segment_id},
                            {"inliers", d.inliers},
                            {"seen_through", d.seen_through}});
  }
  return j;
}

// Per plane: area before and after growth, and the cells added by texture
// evidence and as plain bridges.
nlohmann::json GrowthJson(const PlaneGrowthReport& growth) {
  nlohmann::json planes = nlohmann::json::array();
  for (const PlaneGrowthStats& p : growth.planes) {
    planes.push_back({{"plane_id", p.plane_id},
                      {"cell_m", p.cell_m},
                      {"area_before_m2", p.area_before_m2},
                      {"area_after_m2", p.area_after_m2},
                      {"cells_textured", p.cells_textured},
                      {"cells_plain", p.cells_plain},
                      {"cells_carved", p.cells_carved},
                      {"cells_hidden", p.cells_hidden}});
  }
  nlohmann::json hypotheses = nlohmann::json::array();
  for (const HypothesisStats& h : growth.hypotheses) {
    hypotheses.push_back({{"inliers", h.inliers},
                          {"cells_textured", h.cells_textured},
                          {"cells_inconsistent", h.cells_inconsistent},
                          {"offset_ncc_gain", h.offset_ncc_gain},
                          {"confirmed", h.confirmed},
                          {"plane_id", h.plane_id},
                          {"area_m2", h.area_m2}});
  }
  return {{"views", growth.views},
          {"exposure_gain_min", growth.min_exposure_gain},
          {"exposure_gain_max", growth.max_exposure_gain},
          {"seconds", growth.seconds},
          {"planes", planes},
          {"hypotheses", hypotheses}};
}

nlohmann::json MosaicsJson(const MosaicReport& mosaic) {
  nlohmann::json mosaics = nlohmann::json::array();
  for (const auto& m : mosaic.planes) {
    mosaics.push_back(
        {{"plane_id", m.plane_id},
         {"pixels_per_meter", m.pixels_per_meter},
         {"width", m.width},
         {"height", m.height},
         {"frames", m.frames},
         {"coverage", m.coverage},
         {"features", m.num_features},
         {"feature_residual_median_px", m.feature_residual_median_px},
         {"feature_residual_max_px", m.feature_residual_max_px}});
  }
  return mosaics;
}

nlohmann::json ExportedPointsJson(const PointTrustReport& point_trust) {
  return {{"points", point_trust.num_points},
          {"exported", point_trust.num_exported},
          {"keep_all_points", point_trust.keep_all},
          {"reprojection_limit_px", point_trust.reprojection_limit_px},
          // Per reason: left out, or with keep_all_points exported untrusted.
          {point_trust.keep_all ? "untrusted_kept" : "left_out",
           {{"short_track", point_trust.short_track},
            {"reprojection_error", point_trust.reprojection_error},
            {"triangulation_angle", point_trust.triangulation_angle},
            {"uncertainty", point_trust.uncertainty}}}};
}

nlohmann::json InlierRefinementJson(const InlierRefinementReport& r) {
  return {{"enabled", r.enabled},
          {"moved", r.num_moved},
          {"median_move_m", r.median_move_m},
          {"max_move_m", r.max_move_m},
          {"median_relative_offset", r.median_relative_offset}};
}

}  // namespace

nlohmann::json MappingReport::ToJson() const {
  nlohmann::json j;
  j["num_frames"] = num_frames;
  j["tracking"] = TrackingJson(tracking);
  j["observations_beyond_radius"] = observations_beyond_radius;
  j["triangulation"] = {
      {"tracks_in", triangulation.num_tracks},
      {"points", triangulation.num_points},
      {"rejected_short", triangulation.rejected_short},
      {"rejected_failed", triangulation.rejected_failed},
      {"rejected_angle", triangulation.rejected_angle},
      {"rejected_reprojection", triangulation.rejected_reprojection},
      {"rejected_cheirality", triangulation.rejected_cheirality},
      {"mean_reprojection_error_px", triangulation.mean_reprojection_error_px},
      {"median_reprojection_error_px",
       triangulation.median_reprojection_error_px}};
  j["retriangulation"] = {
      {"points", retriangulation.num_points},
      {"rejected_reprojection", retriangulation.rejected_reprojection},
      {"rejected_angle", retriangulation.rejected_angle},
      {"mean_reprojection_error_px",
       retriangulation.mean_reprojection_error_px}};
  j["bundle_adjustment"] = BundleAdjustmentJson(bundle_adjustment);
  j["planes"] = PlanesJson(planes);
  j["see_through"] = SeeThroughJson(see_through);
  j["plane_growth"] = GrowthJson(growth);
  j["homographies"] = {
      {"count", homographies.num_homographies},
      {"checked", homographies.num_checked},
      {"refined", homographies.num_refined},
      {"median_residual_before_px", homographies.median_residual_before_px},
      {"median_residual_after_px", homographies.median_residual_after_px}};
  j["mosaics"] = MosaicsJson(mosaic);
  j["exported_points"] = ExportedPointsJson(point_trust);
  j["inlier_refinement"] = InlierRefinementJson(inlier_refinement);
  nlohmann::json t = nlohmann::json::object();
  for (const auto& s : timings) t[s.name] = s.seconds;
  j["timings_seconds"] = t;
  j["total_seconds"] = total_seconds;
  j["frames_per_second"] = total_seconds > 0 ? num_frames / total_seconds : 0.0;
  return j;
}

void WriteMappingResult(const std::filesystem::path& dir,
                        const MappingResult& result) {
  AtomicDirectory out(dir, "map");
  WriteMap(out.path(), result.map);
  // Streamed: the directory appears whole or not at all anyway.
  const std::filesystem::path features = out.path() / "features.csv";
  std::ofstream stream(features, std::ios::binary);
  WriteFeatureTable(stream, result.tracks);
  stream.flush();
  if (!stream) throw OutputError(features.string() + ": write failed");
  out.Commit();
}

}  // namespace monomap
