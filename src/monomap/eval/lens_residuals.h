// Is the lens calibration right at the rim? Given poses that can be
// trusted (e.g. from a checkerboard, `eval board-poses`), each track is
// triangulated from its observations near the image centre only, then its
// observations everywhere are compared with where that point projects,
// binned by distance from the principal point. A right calibration leaves
// residuals of zero mean in every ring; one that is off shows a radial
// offset growing toward the rim, which a bundle adjustment hides by
// bending the poses (see BundleAdjustmentOptions::refine_distortion).
#pragma once

#include <vector>

#include "monomap/camera/camera.h"
#include "monomap/geometry/rigid3.h"
#include "monomap/map/map.h"

namespace monomap {

struct LensResidualOptions {
  // Observations within this distance (px) of the principal point fix the
  // point; the others are only measured.
  double centre_radius_px = 200.0;
  // Width (px) of the rings.
  double ring_px = 40.0;
  // Tracks with fewer central observations are skipped.
  int min_centre_observations = 10;
  // Tracks whose central observations fit worse than this (median, px)
  // are skipped as mistracks.
  double max_centre_median_px = 0.3;
  void Check() const;
};

struct LensResidualRing {
  double min_radius_px = 0.0;
  double max_radius_px = 0.0;
  int count = 0;
  // Residual (observed minus projected) along the outward radial direction
  // and perpendicular to it (counter-clockwise in the image), px.
  double radial_mean_px = 0.0;
  double radial_median_px = 0.0;
  double tangential_median_px = 0.0;
};

struct LensResidualReport {
  int tracks_used = 0;
  std::vector<LensResidualRing> rings;  // rings with observations only
};

// `world_from_cam` is indexed by the tracks' frame numbers; observations of
// frames beyond it are ignored.
LensResidualReport EvaluateLensResiduals(
    const Camera& camera, const std::vector<Rigid3d>& world_from_cam,
    const std::vector<Track>& tracks, const LensResidualOptions& options);

}  // namespace monomap
