// Stage 1 of map building: KLT feature tracking (Lucas-Kanade-Tomasi in the
// spirit of Birchfield's KLT tracker) on the raw, distorted images.
//
// Features are Shi-Tomasi corners (cv::goodFeaturesToTrack) tracked from
// frame to frame with pyramidal Lucas-Kanade (cv::calcOpticalFlowPyrLK),
// forward and backward: a feature whose backward track does not return to
// where it started is dropped, which removes features on occlusion
// boundaries and on content that changed (a hand entering the view) instead
// of letting them drift. Lost features are replaced by new corners detected
// in the parts of the image that have too few, so the features stay spread
// over the image. After the frame-to-frame step every feature is aligned
// with its reference patch by an affine-photometric Lucas-Kanade
// (feature_template.h), which keeps frame-to-frame errors from adding up
// into drift. A feature that stops aligning with its reference (twice in a
// row) goes on under a new id: one track stays one scene point, which the
// frame-to-frame check alone does not ensure for a point on an occlusion
// boundary or an edge that slides slowly. Output pixels are raw (distorted);
// the geometric stages undistort them.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <opencv2/core.hpp>
#include <utility>
#include <vector>

#include "monomap/map/map.h"
#include "monomap/tracking/feature_template.h"

namespace monomap {

struct KltTrackerOptions {
  // Number of features the tracker keeps alive in every frame when the
  // images have enough corners; lost ones are replaced, never more.
  int target_features = 600;
  // New corners are detected only once at least this many features are
  // missing from target_features (1: every frame short of it). Detection
  // costs a corner response over the whole image; waiting for 20 of 600
  // took the desk build from ~10 s to ~8.5 s with equal accuracy.
  int detection_min_missing = 20;
  // Shi-Tomasi quality level: corners weaker than this fraction of the
  // strongest corner in the searched area are not detected.
  double quality_level = 0.01;
  // Minimum distance (px) between a new corner and any other feature, so
  // features do not duplicate each other.
  double min_distance_px = 10.0;
  // Window (px) of the corner-response sum in goodFeaturesToTrack.
  int detection_block_size = 3;
  // Side (px, odd) of the Lucas-Kanade window.
  int window_size = 21;
  // Pyramid levels above the full-resolution image (0 = no pyramid).
  int pyramid_levels = 3;
  // Largest LK iterations per pyramid level.
  int lk_max_iterations = 30;
  // LK stops when the update is smaller than this (px).
  double lk_epsilon = 0.01;
  // LK refuses windows whose gradient matrix' smallest eigenvalue (divided
  // by the window area) is below this: flat areas cannot be tracked.
  double lk_min_eigen_threshold = 1e-4;
  // Largest distance (px) between a feature and its forward-then-backward
  // tracked position; above it the track is deemed wrong and dropped.
  double forward_backward_threshold_px = 1.0;
  // Largest LK error (mean absolute grey difference per window pixel);
  // <= 0 disables the test.
  double max_lk_error = 50.0;
  // Features closer than this (px) to the image border are dropped and none
  // are detected there: their LK window would reach outside the image.
  double border_margin_px = 8.0;
  // Detection grid: each of grid_cols x grid_rows cells is entitled to
  // target_features / (cols*rows) features, so replacements are spread over
  // the image rather than piled up in its most textured corner.
  int grid_cols = 6;
  int grid_rows = 4;
  // Align each tracked feature with its reference patch (affine warp,
  // normalized intensities) after the frame-to-frame step: no drift.
  bool affine_refinement = true;
  // Options of that alignment.
  AffineRefinementOptions affine;
  // A feature is aligned every n-th frame (staggered over the features, so
  // every frame does 1/n of them); the frames in between get the
  // correction interpolated, since drift grows smoothly. 1: every frame.
  int affine_interval = 1;
  // The reference patch is taken again from the current frame when the
  // warp has scaled it by more than this factor in some direction (or
  // less than its inverse), or when alignments fail (alignment_retries): a
  // reference seen too differently no longer aligns well.
  double max_affine_scale = 1.3;
  // Estimate the images' noise from the first frame
  // (EstimateImageNoiseSigma) and use it as affine.noise_sigma; false:
  // affine.noise_sigma as given.
  bool estimate_noise = true;
  // A failed alignment keeps the reference for this many more frames (a
  // blurred frame, a passing highlight); the frames in between get the
  // next successful alignment's correction spread over them. Only then is
  // the reference given up.
  int alignment_retries = 1;
  // A feature whose reference is given up after failed alignments (the
  // aligned patch no longer matches: a point on an occlusion boundary or
  // an edge sliding) goes on under a new id from where frame-to-frame
  // tracking put it, since it may no longer be the point it was; false: it
  // keeps its id and only its reference is taken again.
  bool split_on_failed_alignment = true;

  void Check() const;
};

// Counts for one call of KltTracker::Track.
struct KltFrameStats {
  int frame = 0;
  int tracked = 0;     // features carried over from the previous frame
  int lost_lk = 0;     // LK failed (status 0 or flat window)
  int lost_error = 0;  // LK error above max_lk_error
  int lost_forward_backward = 0;  // forward-backward error too large
  int lost_border = 0;            // left the image (or its margin)
  int detected = 0;               // new features started in this frame
  int refined = 0;                // positions corrected by the affine alignment
  int reanchored = 0;             // reference patches taken again
  int split = 0;  // features given a new id after a failed alignment
  int total = 0;                  // features alive after this frame
};

// A feature alive in the current frame.
struct KltFeature {
  FeatureId id = 0;
  Eigen::Vector2d px = Eigen::Vector2d::Zero();  // raw pixel
};

class KltTracker {
 public:
  explicit KltTracker(const KltTrackerOptions& options = {});

  // Tracks into frame `frame_index` (8-bit single-channel image, all frames
  // of equal size). The first call only detects. Frame indices must
  // increase; they are stored in the observations as given. Throws
  // InputError for an image of the wrong type or size.
  void Track(int frame_index, const cv::Mat& grey);

  // The same with the image pyramid already built by BuildPyramid (lets a
  // caller build pyramids in parallel with tracking).
  void Track(int frame_index, const cv::Mat& grey,
             std::vector<cv::Mat> pyramid);

  // Builds the LK pyramid (with derivatives) Track expects.
  static std::vector<cv::Mat> BuildPyramid(const cv::Mat& grey,
                                           const KltTrackerOptions& options);
  // The same into `pyramid`, reusing its buffers when they fit.
  static void BuildPyramid(const cv::Mat& grey,
                           const KltTrackerOptions& options,
                           std::vector<cv::Mat>* pyramid);
  // Hands out the pyramid of the frame before the previous one (no longer
  // needed) so a caller can build the next pyramid into its buffers. Empty
  // if there is none.
  std::vector<cv::Mat> ReleaseSparePyramid() {
    std::vector<cv::Mat> spare = std::move(spare_pyramid_);
    spare_pyramid_.clear();
    return spare;
  }

  // Features alive after the last Track call.
  std::vector<KltFeature> Features() const;
  int NumFeatures() const { return static_cast<int>(active_.size()); }

  // All tracks so far, ended and still alive, sorted by id. Tracks with
  // fewer than `min_length` observations are left out.
  std::vector<monomap::Track> FinishedTracks(int min_length = 1) const;

  const KltFrameStats& LastFrameStats() const { return last_stats_; }
  // Sums over all frames so far (`frame` holds the number of frames).
  const KltFrameStats& TotalStats() const { return total_stats_; }
  // Number of ids handed out so far (ids are 0, 1, 2, ...).
  int64_t NumTracksCreated() const { return next_id_; }
  // The images' noise (grey levels) the alignment allows for.
  double NoiseSigma() const { return options_.affine.noise_sigma; }

 private:
  struct Active {
    FeatureId id = 0;
    cv::Point2f px;
    // Reference patch and the warp that maps it into the last frame.
    FeatureTemplate reference;
    Eigen::Matrix2f warp = Eigen::Matrix2f::Identity();
    int reference_frame = 0;  // frame of the last alignment or reference
    int failures = 0;         // failed alignments in a row
  };
  // What RefineFeature did.
  struct Refinement {
    bool refined = false;     // aligned with its reference
    bool reanchored = false;  // a new reference taken
    bool failed = false;      // its reference given up after failures
  };
  // Affine alignment of `f` into `grey` (see KltTrackerOptions).
  Refinement RefineFeature(const cv::Mat& grey, Active* f) const;
  // Gives `f` a new id and an empty track (split_on_failed_alignment).
  void RenewId(Active* f);
  // Throws InputError naming the frame if it cannot follow the last one.
  void CheckFrame(int frame_index, const cv::Mat& grey,
                  const std::vector<cv::Mat>& pyramid) const;
  // Tracks the active features into `pyramid` (forward, then backward
  // from the survivors); drops the lost ones, counting why in *stats.
  void TrackActive(const std::vector<cv::Mat>& pyramid, KltFrameStats* stats);
  // Keeps the forward-tracked features (indices forward_ok, at fwd_pts)
  // whose backward track returns and that stay inside the margin.
  void KeepTracked(const std::vector<size_t>& forward_ok,
                   const std::vector<cv::Point2f>& fwd_pts,
                   const std::vector<cv::Point2f>& back_pts,
                   const std::vector<uchar>& back_status, KltFrameStats* stats);
  // Affine refinement of the features due this frame; spreads each
  // correction over the observations since their last alignment.
  void RefineActive(int frame_index, const cv::Mat& grey, KltFrameStats* stats);
  void Detect(int frame_index, const cv::Mat& grey, KltFrameStats* stats);
  // Detection grid cell of a pixel.
  int CellOf(const cv::Point2f& p) const;
  // mask_: inside the margin, away from active features. False if the
  // margin leaves no image.
  bool BuildDetectionMask();
  // A new feature and track at `corner`.
  void StartFeature(int frame_index, const cv::Mat& grey,
                    const cv::Point2f& corner);

  KltTrackerOptions options_;  // affine.noise_sigma set by the first frame
  int last_frame_ = -1;
  cv::Size size_;
  std::vector<cv::Mat> prev_pyramid_;
  std::vector<cv::Mat> spare_pyramid_;  // buffers to build the next one in
  cv::Mat mask_;                        // detection mask, reused
  std::vector<Active> active_;
  std::vector<monomap::Track> tracks_;  // index = id
  FeatureId next_id_ = 0;
  KltFrameStats last_stats_;
  KltFrameStats total_stats_;
};

// Summary of tracking a sequence.
struct TrackingReport {
  int frames = 0;
  int64_t tracks_created = 0;
  // Over the returned tracks (those with >= 2 observations).
  int64_t tracks_returned = 0;
  double mean_track_length = 0.0;
  double median_track_length = 0.0;
  double mean_features_per_frame = 0.0;
  int64_t lost_forward_backward = 0;
  int64_t lost_lk = 0;
  int64_t lost_border = 0;
  // Affine alignments accepted, and reference patches taken again.
  int64_t refined = 0;
  int64_t reanchored = 0;
  // Features that went on under a new id after a failed alignment.
  int64_t split = 0;
  // The images' noise (grey levels) the alignment allowed for.
  double noise_sigma = 0.0;
  double seconds = 0.0;
  double frames_per_second = 0.0;
};

// Tracks frames 0 .. num_frames-1 given by `load_grey` (called from several
// threads at once, must be thread-safe; returns an 8-bit grey image). Image
// decoding and pyramid building run in parallel with the serial tracking
// (oneTBB pipeline). Fills `tracks` with the tracks of at least two
// observations, sorted by id. Within the tracking stage, Lucas-Kanade runs
// over chunks of the features in parallel (same result as one call). Throws
// what load_grey throws, InputError for
// bad images, StageError if num_frames < 1.
TrackingReport TrackFeatures(const std::function<cv::Mat(int)>& load_grey,
                             int num_frames, const KltTrackerOptions& options,
                             std::vector<Track>* tracks);

}  // namespace monomap
