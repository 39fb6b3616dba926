// MappingPipeline: dataset in, map out. Runs the stages in order (track,
// triangulate, bundle-adjust, fit planes, homographies, mosaics) and
// collects their reports and timings.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "monomap/io/dataset.h"
#include "monomap/map/map.h"
#include "monomap/planes/inlier_refinement.h"
#include "monomap/planes/plane_fitting.h"
#include "monomap/planes/plane_growth.h"
#include "monomap/planes/plane_hypotheses.h"
#include "monomap/planes/see_through.h"
#include "monomap/texture/image_plane_homography.h"
#include "monomap/texture/mosaic.h"
#include "monomap/tracking/klt_tracker.h"
#include "monomap/triangulation/bundle_adjustment.h"
#include "monomap/triangulation/keyframe_adjustment.h"
#include "monomap/triangulation/point_trust.h"
#include "monomap/triangulation/triangulator.h"

namespace monomap {

struct MappingOptions {
  // Stage 1: KLT tracking.
  KltTrackerOptions tracking;
  // Stage 2: triangulation of tracks with odometry poses.
  TriangulationOptions triangulation;
  // Stage 2b: bundle adjustment with odometry priors (enabled by default).
  BundleAdjustmentOptions bundle_adjustment;
  // Stage 3: RANSAC planes.
  PlaneFittingOptions planes;
  // Stage 3a: segments the cameras saw through are dropped.
  SeeThroughOptions see_through;
  // Stage 3b: plane polygons grown over the image regions their plane
  // explains.
  PlaneGrowthOptions growth;
  // Stage 3c (with growth): planes along the scene's directions through
  // landmarks on no plane, kept where the images confirm them.
  PlaneHypothesisOptions hypotheses;
  // Stage 4: image-to-plane homographies.
  HomographyOptions homographies;
  // Stage 5: texture mosaics.
  MosaicOptions mosaic;
  // Last: which points the map exports (untrusted ones left out unless
  // point_trust.keep_all). Planes and textures use every point.
  PointTrustOptions point_trust;
  // Then the exported plane inliers move to their plane's local offset.
  InlierRefinementOptions inlier_refinement;
  // The first triangulation (against odometry poses, before bundle
  // adjustment) accepts reprojection errors this many times larger.
  double first_pass_error_factor = 4.0;
  // Observations farther than this from the principal point (raw px) are
  // left out of triangulation, bundle adjustment, the homographies and the
  // mosaics' feature checks (0: none left out); the feature table keeps
  // them. Set it to where the calibration is known: a lens fitted on board
  // views is extrapolated beyond the corners they reached, and a few rim
  // observations then bend every pose (ObservationsWithinRadius).
  double max_observation_radius_px = 0.0;
  // Bundle adjustment runs on keyframes (every n-th frame, spaced by
  // travel on long sequences); the other frames get the interpolated
  // correction of their neighbours.
  KeyframeOptions keyframes;
  // Stop after triangulation + bundle adjustment (a point map only).
  bool points_only = false;
  // Draw progress bars on stderr (only when it is a terminal).
  bool show_progress = true;

  void Check() const;
};

// Wall-clock seconds of one stage.
struct StageTiming {
  std::string name;
  double seconds = 0.0;
};

struct MappingReport {
  int num_frames = 0;
  TrackingReport tracking;
  // Observations beyond max_observation_radius_px, left out of the geometry.
  int64_t observations_beyond_radius = 0;
  TriangulationReport triangulation;
  BundleAdjustmentReport bundle_adjustment;
  // Triangulation against the adjusted poses (strict thresholds).
  TriangulationReport retriangulation;
  PlaneFittingReport planes;
  SeeThroughReport see_through;
  PlaneGrowthReport growth;
  HomographyReport homographies;
  MosaicReport mosaic;
  // Points exported and left out (by reason) by the trust filter.
  PointTrustReport point_trust;
  // How far the exported plane inliers moved onto their planes.
  InlierRefinementReport inlier_refinement;
  std::vector<StageTiming> timings;
  double total_seconds = 0.0;

  nlohmann::json ToJson() const;
};

struct MappingResult {
  Map map;
  std::vector<Track> tracks;
  // Fitted from every point: inlier ids may name landmarks the export's
  // trust filter left out of map.landmarks.
  std::vector<PlaneSegment> segments;
  // Odometry poses the map was built from (world_from_cam per frame).
  std::vector<Rigid3d> odometry_world_from_cam;
  MappingReport report;
};

// Whether two calibrations are the same (every field equal).
bool SameCalibration(const Camera& a, const Camera& b);

// Builds the map. Throws InputError on bad data, StageError if a stage
// cannot produce anything (e.g. no features).
MappingResult BuildMap(const Dataset& dataset, const MappingOptions& options);

// Writes the map directory atomically: the directory appears complete or
// not at all (an existing one is replaced only on success). Also writes
// the feature table (features.csv).
void WriteMappingResult(const std::filesystem::path& dir,
                        const MappingResult& result);

}  // namespace monomap
