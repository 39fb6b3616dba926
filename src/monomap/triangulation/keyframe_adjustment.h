// Bundle adjustment over keyframes: the reduced camera system of all frames
// is a wide band (tracks span tens of frames) and its factorization
// dominated the build; neighbouring frames add little information. The
// keyframes' corrections are interpolated onto the frames between them
// (odometry is smooth over a few frames).
//
// Keyframes are every `interval`-th frame. On a long sequence (more such
// keyframes than long_sequence_min_keyframes) they are also spaced by the
// odometry's travel: on a slow run a point stays in view for hundreds of
// frames, the band's width grows with it, and the factorization with the
// sequence times the width squared. Spacing by travel bounds the width, so
// the adjustment's time and memory grow linearly with the path
// (docs/benchmarks.md, "Long runs").
//
// A slow run shorter than that has the same problem: tracks span so many
// keyframes that forming the reduced camera system (a 6x6 product per pair
// of a point's observations) and factoring it (dense once far points are
// seen by every keyframe) grow faster than the sequence. So keyframes are
// also thinned, every m-th kept, until a point is seen by at most
// max_covisibility keyframes on average; that bound is scale-free (a slow
// desk and a slow hallway alike). Sequences below it keep the plain interval,
// so their maps do not change.
#pragma once

#include <vector>

#include "monomap/camera/camera.h"
#include "monomap/geometry/rigid3.h"
#include "monomap/map/map.h"
#include "monomap/triangulation/bundle_adjustment.h"

namespace monomap {

struct KeyframeOptions {
  // Every n-th frame is a keyframe (1: all frames), and the last.
  int interval = 3;
  // Above this many keyframes (0: never) a frame is a keyframe only if the
  // odometry also moved at least long_min_distance_m or turned at least
  // long_min_angle_deg since the previous keyframe.
  int long_sequence_min_keyframes = 400;
  // Travel (m) between keyframes on a long sequence: a robot at 0.4 m/s
  // filmed at 30 Hz moves this much in 3 frames.
  double long_min_distance_m = 0.04;
  // Rotation (degrees) that also makes a keyframe on a long sequence.
  double long_min_angle_deg = 1.0;
  // Keep every m-th keyframe (smallest m) so that the tracks' mean number
  // of keyframes over their observations (sum k^2 / sum k, as
  // BundleAdjustmentReport::covisibility) is at most this (0: never).
  // Above every sequence of the benchmark set, whose maps stay as they were
  // (docs/benchmarks.md, "Long runs").
  double max_covisibility = 80.0;

  // Throws OptionsError naming the field if a value makes no sense.
  void Check() const;
};

// Indices of the keyframes (ascending; the first and last frame always)
// for odometry poses world_from_cam, before thinning (ThinKeyframes).
std::vector<int> SelectKeyframes(const std::vector<Rigid3d>& world_from_cam,
                                 const KeyframeOptions& options);

// Mean number of keyframes seeing a track, over its keyframe observations
// (sum k^2 / sum k over tracks seen by >= 3 keyframes; 0 if none).
// `keyframes` ascending, frame indices of `tracks`.
double KeyframeCovisibility(const std::vector<Track>& tracks,
                            const std::vector<int>& keyframes, int num_frames);

// `keyframes` with every m-th kept (and the last) for the smallest m that
// brings KeyframeCovisibility to options.max_covisibility or below; m is
// written to *thinning (1: unchanged).
std::vector<int> ThinKeyframes(const std::vector<Track>& tracks,
                               const std::vector<int>& keyframes,
                               int num_frames, const KeyframeOptions& options,
                               int* thinning);

// BundleAdjust over the (thinned) keyframes' observations and poses; the other
// frames get the interpolated world-side correction of the keyframes
// around them. *landmarks keeps only those adjusted (seen by >= 3
// keyframes); the caller triangulates the tracks again. With every frame a
// keyframe, plain BundleAdjust.
BundleAdjustmentReport BundleAdjustKeyframes(
    const Camera& camera, const std::vector<Track>& tracks,
    const BundleAdjustmentOptions& options,
    const KeyframeOptions& keyframe_options,
    std::vector<Rigid3d>* world_from_cam, std::vector<Landmark>* landmarks);

}  // namespace monomap
