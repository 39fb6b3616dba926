// Stage 5: one texture mosaic per plane, blended from many frames robustly
// (moving objects and specular highlights seen in a minority of frames
// vanish), with occlusion by the other planes taken into account.
#pragma once

#include <functional>
#include <vector>

#include <opencv2/core.hpp>

#include "monomap/camera/camera.h"
#include "monomap/geometry/rigid3.h"
#include "monomap/map/map.h"
#include "monomap/texture/image_plane_homography.h"

namespace monomap {

enum class BlendMode {
  kRobust,  // mean of the samples within a band around the median (default)
  kMedian,  // per-channel median
  kMean,    // plain average (for comparison; not robust)
};

struct MosaicOptions {
  // Texture resolution; 0 = automatic: median over the blended frames of
  // the image resolution at the plane centre, capped below.
  double pixels_per_meter = 0.0;
  // Upper bound of the automatic resolution (pixels per metre).
  double max_pixels_per_meter = 2000.0;
  // Upper bound of the texture width and height (pixels).
  int max_texture_side = 4096;
  // Frames blended per plane, chosen evenly over the frames that see it.
  int max_frames_per_plane = 40;
  // How to blend the samples of a texel.
  BlendMode blend = BlendMode::kRobust;
  // Robust band: samples within max(k * 1.4826 * MAD, min_band) of the
  // median luminance are averaged.
  double robust_mad_k = 2.5;
  // Lower bound of the robust band (grey levels): noise and residual
  // exposure differences must not reject good samples.
  double robust_min_band = 8.0;
  // Per-frame gain compensation (exposure changes between frames).
  bool gain_compensation = true;
  // Texels sampled per plane to estimate the gains.
  int gain_samples = 4000;
  // Reject samples seen at grazing angles: |cos(ray, normal)| below this.
  double min_cos_view_angle = 0.15;
  // Reject samples where another plane's polygon is hit first along the
  // viewing ray, closer by more than occlusion_margin_m.
  bool occlusion_test = true;
  // Depth margin (m) of the occlusion test, so that planes meeting at an
  // edge do not occlude each other there.
  double occlusion_margin_m = 0.01;
  // Samples closer than this to the image border (pixels) are not used.
  double image_margin_px = 1.0;

  void Check() const;
};

// Per-plane mosaic figures.
struct PlaneMosaicStats {
  int plane_id = 0;
  double pixels_per_meter = 0.0;
  int width = 0;
  int height = 0;
  std::vector<int> frames;  // frames blended
  // Fraction of the texels inside the polygon seen by at least one frame.
  double coverage = 0.0;
  int num_features = 0;  // features with an alignment residual
  // Distance (texture pixels) between a feature's texture_px and the median
  // of its observations mapped into the texture.
  double feature_residual_mean_px = 0.0;
  double feature_residual_median_px = 0.0;
  double feature_residual_max_px = 0.0;
};

struct MosaicReport {
  std::vector<PlaneMosaicStats> planes;
  int num_planes_skipped = 0;  // no frame sees them
  double seconds = 0.0;
};

// Loads the raw (distorted) image of a frame: 8-bit grey or BGR. Called
// from several threads at once (images are decoded in parallel).
using ImageLoader = std::function<cv::Mat(int frame)>;

// Builds one TexturedPlane per segment that some frame sees (same id,
// plane and polygon; frame origin moved to the polygon's min corner so that
// texture coordinates are positive). `homographies` come from
// ComputeImagePlaneHomographies: they say which frames see which plane and
// map plane coordinates to undistorted pixels. Throws InputError if a
// loaded image is empty or not of the camera's size.
MosaicReport BuildTexturedPlanes(
    const Camera& camera, const std::vector<Rigid3d>& world_from_cam,
    const std::vector<PlaneSegment>& segments,
    const std::vector<Landmark>& landmarks, const std::vector<Track>& tracks,
    const std::vector<ImagePlaneHomography>& homographies,
    const ImageLoader& load_image, const MosaicOptions& options,
    std::vector<TexturedPlane>* planes);

}  // namespace monomap
