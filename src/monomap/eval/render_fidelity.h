// Texture fidelity of a map: render it from known camera poses (ground
// truth of frames the map did not texture from, e.g. a second traversal)
// and compare each render with the real image the camera took there.
//
// Per frame, over the pixels where the render shows the map:
//  * NCC (zero-mean normalized cross-correlation), blind to gain and
//    offset, as the localization measurement model sees it;
//  * PSNR after a least-squares gain and offset of the render to the image
//    (exposure changes between frames are not a texture error).
// The real image is undistorted to the pinhole camera the renderer uses.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "monomap/camera/camera.h"
#include "monomap/eval/point_accuracy.h"
#include "monomap/geometry/rigid3.h"
#include "monomap/map/map.h"

namespace monomap {

struct RenderFidelityOptions {
  // Render and compare at this width (the camera's aspect is kept; 0 or
  // more than the camera's width: the camera's size).
  int width = 320;
  // Frames whose render shows the map on less than this fraction of the
  // pixels are skipped (too little to compare).
  double min_coverage = 0.2;

  void Check() const;
};

// One compared frame.
struct FrameFidelity {
  int frame = 0;          // index given by the caller
  double coverage = 0.0;  // map pixels / pixels
  double ncc = 0.0;
  double psnr_db = 0.0;
};

struct RenderFidelity {
  std::vector<FrameFidelity> frames;  // compared frames, in input order
  int skipped = 0;                    // below min_coverage
  ErrorStats ncc;                     // over compared frames
  ErrorStats psnr_db;
  ErrorStats coverage;
};

// Compares the map's render at world_from_cam[i] with images[i] (raw,
// distorted, 8-bit grey or BGR, of `camera`'s size); frames[i] is the
// index reported for it. Throws InputError for images of the wrong size or
// type, or mismatched list sizes, OptionsError for bad options.
RenderFidelity EvaluateRenderFidelity(const Map& map, const Camera& camera,
                                      const std::vector<Rigid3d>& world_from_cam,
                                      const std::vector<cv::Mat>& images,
                                      const std::vector<int>& frames,
                                      const RenderFidelityOptions& options);

// Each pose moved `offset_m` along its own camera x axis: a wrong pose to
// render from, to see how much better the true one matches.
std::vector<Rigid3d> MovedAlongCameraX(
    const std::vector<Rigid3d>& world_from_cam, double offset_m);

// Whether renders tell the true pose from a wrong one: a render that
// matched any pose equally well would say nothing about where the camera
// is.
struct PoseDiscrimination {
  int compared = 0;     // frames compared from both poses
  int true_better = 0;  // of which the true pose's render has a higher NCC
  // true_better / compared (0 if none compared).
  double TrueBetterShare() const {
    return compared > 0 ? static_cast<double>(true_better) / compared : 0.0;
  }
};

// Frame by frame (matched by FrameFidelity::frame): `truth` and `wrong`
// are EvaluateRenderFidelity of the same frames from the true and the
// wrong poses.
PoseDiscrimination ComparePoses(const RenderFidelity& truth,
                                const RenderFidelity& wrong);

// NCC and gain/offset-compensated PSNR of `render` against `image` (both
// CV_8UC1, same size) over mask != 0; false if fewer than 2 pixels or one
// of them is constant there.
bool CompareMasked(const cv::Mat& render, const cv::Mat& image,
                   const cv::Mat& mask, double* ncc, double* psnr_db);

}  // namespace monomap
