#include "monomap/tracking/klt_tracker.h"

#include <tbb/blocked_range.h>
#include <tbb/concurrent_queue.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_pipeline.h>

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <string>
#include <utility>

#include "monomap/tracking/pyramidal_lk.h"
#include "monomap/util/error.h"
#include "monomap/util/progress.h"
#include "monomap/util/stats.h"

namespace monomap {

void KltTrackerOptions::Check() const {
  CheckOption(target_features >= 1, "target_features", "must be >= 1");
  CheckOption(quality_level > 0.0 && quality_level < 1.0, "quality_level",
              "must be in (0, 1)");
  CheckOption(min_distance_px >= 0.0, "min_distance_px", "must be >= 0");
  CheckOption(detection_block_size >= 3, "detection_block_size",
              "must be >= 3");
  CheckOption(window_size >= 3 && window_size % 2 == 1, "window_size",
              "must be odd and >= 3");
  CheckOption(pyramid_levels >= 0 && pyramid_levels <= 10, "pyramid_levels",
              "must be in [0, 10]");
  CheckOption(lk_max_iterations >= 1, "lk_max_iterations", "must be >= 1");
  CheckOption(lk_epsilon > 0.0, "lk_epsilon", "must be > 0");
  CheckOption(lk_min_eigen_threshold >= 0.0, "lk_min_eigen_threshold",
              "must be >= 0");
  CheckOption(forward_backward_threshold_px > 0.0,
              "forward_backward_threshold_px", "must be > 0");
  CheckOption(border_margin_px >= 0.0, "border_margin_px", "must be >= 0");
  CheckOption(detection_min_missing >= 1, "detection_min_missing",
              "must be >= 1");
  CheckOption(grid_cols >= 1 && grid_rows >= 1, "grid_cols/grid_rows",
              "must be >= 1");
  affine.Check();
  CheckOption(affine_interval >= 1, "affine_interval", "must be >= 1");
  CheckOption(max_affine_scale > 1.0, "max_affine_scale", "must be > 1");
  CheckOption(alignment_retries >= 0, "alignment_retries", "must be >= 0");
}

namespace {

// The Lucas-Kanade settings of the tracker's options.
PyrLkOptions LkOptions(const KltTrackerOptions& options) {
  PyrLkOptions lk;
  lk.window = options.window_size;
  lk.levels = options.pyramid_levels;
  lk.max_iterations = options.lk_max_iterations;
  lk.epsilon = options.lk_epsilon;
  lk.min_eigen_threshold = options.lk_min_eigen_threshold;
  return lk;
}

}  // namespace

KltTracker::KltTracker(const KltTrackerOptions& options) : options_(options) {
  options_.Check();
}

std::vector<cv::Mat> KltTracker::BuildPyramid(
    const cv::Mat& grey, const KltTrackerOptions& options) {
  std::vector<cv::Mat> pyramid;
  BuildPyramid(grey, options, &pyramid);
  return pyramid;
}

void KltTracker::BuildPyramid(const cv::Mat& grey,
                              const KltTrackerOptions& options,
                              std::vector<cv::Mat>* pyramid) {
  // With derivatives: the image is the "previous" one of the next frame's
  // forward track and of this frame's backward track, so its gradients are
  // needed twice; computing them here once saves LK doing it twice.
  // Existing buffers of the right size are reused.
  BuildLkPyramid(grey, LkOptions(options), pyramid);
}

void KltTracker::Track(int frame_index, const cv::Mat& grey) {
  std::vector<cv::Mat> pyramid = std::move(spare_pyramid_);
  spare_pyramid_.clear();
  if (!grey.empty()) BuildPyramid(grey, options_, &pyramid);
  Track(frame_index, grey, std::move(pyramid));
}

void KltTracker::Track(int frame_index, const cv::Mat& grey,
                       std::vector<cv::Mat> pyramid) {
  CheckFrame(frame_index, grey, pyramid);
  size_ = grey.size();
  if (last_frame_ < 0 && options_.estimate_noise) {
    options_.affine.noise_sigma = EstimateImageNoiseSigma(grey);
  }

  KltFrameStats stats;
  stats.frame = frame_index;
  if (last_frame_ >= 0 && !active_.empty()) {
    TrackActive(pyramid, &stats);
    if (options_.affine_refinement) RefineActive(frame_index, grey, &stats);
    for (const Active& a : active_) {
      tracks_[static_cast<size_t>(a.id)].observations.push_back(
          {frame_index, Eigen::Vector2d(a.px.x, a.px.y)});
    }
    stats.tracked = static_cast<int>(active_.size());
  }

  Detect(frame_index, grey, &stats);
  stats.total = static_cast<int>(active_.size());

  spare_pyramid_ = std::move(prev_pyramid_);
  prev_pyramid_ = std::move(pyramid);
  last_frame_ = frame_index;
  last_stats_ = stats;
  total_stats_.frame += 1;
  total_stats_.tracked += stats.tracked;
  total_stats_.lost_lk += stats.lost_lk;
  total_stats_.lost_error += stats.lost_error;
  total_stats_.lost_forward_backward += stats.lost_forward_backward;
  total_stats_.lost_border += stats.lost_border;
  total_stats_.detected += stats.detected;
  total_stats_.refined += stats.refined;
  total_stats_.reanchored += stats.reanchored;
  total_stats_.split += stats.split;
  total_stats_.total += stats.total;
}

void KltTracker::CheckFrame(int frame_index, const cv::Mat& grey,
                            const std::vector<cv::Mat>& pyramid) const {
  const std::string where = "frame " + std::to_string(frame_index);
  if (grey.empty() || grey.type() != CV_8UC1) {
    throw InputError(where + ": tracking needs a non-empty 8-bit grey image");
  }
  if (last_frame_ >= 0 && frame_index <= last_frame_) {
    throw InputError(where + ": frame indices must increase (previous " +
                     std::to_string(last_frame_) + ")");
  }
  if (last_frame_ >= 0 && grey.size() != size_) {
    throw InputError(where + ": image size " + std::to_string(grey.cols) + "x" +
                     std::to_string(grey.rows) +
                     " differs from the first frame's");
  }
  if (pyramid.empty()) throw InputError(where + ": empty image pyramid");
}

void KltTracker::TrackActive(const std::vector<cv::Mat>& pyramid,
                             KltFrameStats* stats) {
  std::vector<cv::Point2f> prev_pts(active_.size());
  for (size_t i = 0; i < active_.size(); ++i) prev_pts[i] = active_[i].px;

  std::vector<cv::Point2f> next_pts;
  std::vector<uchar> status;
  std::vector<float> error;
  PyramidalLk(prev_pyramid_, pyramid, prev_pts, &next_pts, &status, &error,
              LkOptions(options_));

  // Backward only for the features that survived the forward track.
  std::vector<size_t> forward_ok;
  std::vector<cv::Point2f> fwd_pts;
  for (size_t i = 0; i < active_.size(); ++i) {
    if (!status[i]) {
      ++stats->lost_lk;
    } else if (options_.max_lk_error > 0.0 &&
               error[i] > options_.max_lk_error) {
      ++stats->lost_error;
    } else {
      forward_ok.push_back(i);
      fwd_pts.push_back(next_pts[i]);
    }
  }
  std::vector<cv::Point2f> back_pts;
  std::vector<uchar> back_status;
  std::vector<float> back_error;
  if (!fwd_pts.empty()) {
    // No initial guess at the original position: starting there would
    // pull the backward track home even from content that changed.
    PyramidalLk(pyramid, prev_pyramid_, fwd_pts, &back_pts, &back_status,
                &back_error, LkOptions(options_));
  }
  KeepTracked(forward_ok, fwd_pts, back_pts, back_status, stats);
}

void KltTracker::KeepTracked(const std::vector<size_t>& forward_ok,
                             const std::vector<cv::Point2f>& fwd_pts,
                             const std::vector<cv::Point2f>& back_pts,
                             const std::vector<uchar>& back_status,
                             KltFrameStats* stats) {
  const double margin = options_.border_margin_px;
  const double max_x = size_.width - 1 - margin;
  const double max_y = size_.height - 1 - margin;
  const double fb2 = options_.forward_backward_threshold_px *
                     options_.forward_backward_threshold_px;
  std::vector<Active> kept;
  kept.reserve(active_.size());
  for (size_t k = 0; k < forward_ok.size(); ++k) {
    Active& a = active_[forward_ok[k]];
    const cv::Point2f p = fwd_pts[k];
    if (!back_status[k]) {
      ++stats->lost_lk;
      continue;
    }
    const cv::Point2f d = back_pts[k] - a.px;
    if (static_cast<double>(d.dot(d)) > fb2 || !std::isfinite(p.x) ||
        !std::isfinite(p.y)) {
      ++stats->lost_forward_backward;
      continue;
    }
    if (p.x < margin || p.y < margin || p.x > max_x || p.y > max_y) {
      ++stats->lost_border;
      continue;
    }
    a.px = p;
    kept.push_back(std::move(a));
  }
  active_ = std::move(kept);
}

void KltTracker::RefineActive(int frame_index, const cv::Mat& grey,
                              KltFrameStats* stats) {
  const int interval = options_.affine_interval;
  std::vector<Refinement> done(active_.size());
  std::vector<cv::Point2f> correction(active_.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, active_.size(), 32),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t i = r.begin(); i != r.end(); ++i) {
                        Active& f = active_[i];
                        if ((frame_index + f.id) % interval != 0) continue;
                        const cv::Point2f before = f.px;
                        done[i] = RefineFeature(grey, &f);
                        correction[i] = f.px - before;
                      }
                    });
  for (size_t i = 0; i < active_.size(); ++i) {
    stats->refined += done[i].refined;
    stats->reanchored += done[i].reanchored;
    Active& f = active_[i];
    if (done[i].failed && options_.split_on_failed_alignment) {
      RenewId(&f);
      ++stats->split;
    }
    if (done[i].refined) {
      // The frames since the last alignment drifted by a growing share
      // of this correction.
      const double span = frame_index - f.reference_frame;
      auto& obs = tracks_[static_cast<size_t>(f.id)].observations;
      for (auto o = obs.rbegin();
           o != obs.rend() && o->frame > f.reference_frame; ++o) {
        const double share = (o->frame - f.reference_frame) / span;
        o->px += share * Eigen::Vector2d(correction[i].x, correction[i].y);
      }
    }
    if (done[i].refined || done[i].reanchored) {
      f.reference_frame = frame_index;
    }
  }
}

void KltTracker::RenewId(Active* f) {
  f->id = next_id_++;
  monomap::Track track;
  track.id = f->id;
  tracks_.push_back(std::move(track));  // this frame's observation follows
}

int KltTracker::CellOf(const cv::Point2f& p) const {
  const int cols = options_.grid_cols;
  const int rows = options_.grid_rows;
  const int cx =
      std::clamp(static_cast<int>(p.x * cols / size_.width), 0, cols - 1);
  const int cy =
      std::clamp(static_cast<int>(p.y * rows / size_.height), 0, rows - 1);
  return cy * cols + cx;
}

bool KltTracker::BuildDetectionMask() {
  // Search only inside the margin and away from existing features (so new
  // ones do not duplicate them).
  const int m = static_cast<int>(std::ceil(options_.border_margin_px));
  const cv::Rect inner(m, m, size_.width - 2 * m, size_.height - 2 * m);
  if (inner.width <= 0 || inner.height <= 0) return false;
  mask_.create(size_, CV_8UC1);  // reused: no page faults every frame
  mask_.setTo(0);
  mask_(inner).setTo(255);
  const int radius = static_cast<int>(std::ceil(options_.min_distance_px));
  if (radius > 0) {
    for (const Active& a : active_) {
      cv::circle(mask_, cv::Point(cvRound(a.px.x), cvRound(a.px.y)), radius,
                 cv::Scalar(0), cv::FILLED);
    }
  }
  return true;
}

void KltTracker::StartFeature(int frame_index, const cv::Mat& grey,
                              const cv::Point2f& corner) {
  const FeatureId id = next_id_++;
  Active a;
  a.id = id;
  a.px = corner;
  a.reference_frame = frame_index;
  if (options_.affine_refinement) {
    a.reference.Extract(grey, Eigen::Vector2f(corner.x, corner.y),
                        options_.affine);
  }
  active_.push_back(std::move(a));
  monomap::Track track;
  track.id = id;
  track.observations.push_back(
      {frame_index, Eigen::Vector2d(corner.x, corner.y)});
  tracks_.push_back(std::move(track));
}

void KltTracker::Detect(int frame_index, const cv::Mat& grey,
                        KltFrameStats* stats) {
  const int num_cells = options_.grid_cols * options_.grid_rows;
  const int quota =
      std::max(1, (options_.target_features + num_cells - 1) / num_cells);
  std::vector<int> count(num_cells, 0);
  for (const Active& a : active_) ++count[CellOf(a.px)];
  int total = static_cast<int>(active_.size());
  // Detection only tops up to the target: features are lost continuously
  // (motion, occlusion), and each top-up serves the short cells first, so
  // the spread recovers without ever exceeding target_features. It waits
  // until detection_min_missing are missing, since every detection
  // computes the corner response of the whole image.
  const int missing = options_.target_features - total;
  if (missing <
      std::clamp(options_.detection_min_missing, 1, options_.target_features)) {
    return;
  }
  if (!BuildDetectionMask()) return;

  // Candidates come sorted by corner strength and mutually spaced by
  // min_distance_px. maxCorners = 0: all of them, since the grid below
  // decides how many each area may take.
  std::vector<cv::Point2f> corners;
  cv::goodFeaturesToTrack(grey, corners, 0, options_.quality_level,
                          options_.min_distance_px, mask_,
                          options_.detection_block_size,
                          /*useHarrisDetector=*/false);

  std::vector<bool> taken(corners.size(), false);
  auto start = [&](size_t k) {
    taken[k] = true;
    StartFeature(frame_index, grey, corners[k]);
    ++count[CellOf(corners[k])];
    ++total;
    ++stats->detected;
  };
  // First fill the cells short of their share (spread over the image) ...
  for (size_t k = 0; k < corners.size() && total < options_.target_features;
       ++k) {
    if (count[CellOf(corners[k])] < quota) start(k);
  }
  // ... then, if textureless cells left the total short, take the
  // strongest remaining corners anywhere.
  for (size_t k = 0; k < corners.size() && total < options_.target_features;
       ++k) {
    if (!taken[k]) start(k);
  }
}

KltTracker::Refinement KltTracker::RefineFeature(const cv::Mat& grey,
                                                 Active* f) const {
  Refinement done;
  Eigen::Vector2f t(f->px.x, f->px.y);
  Eigen::Matrix2f warp = f->warp;
  bool keep_reference = false;
  if (!f->reference.empty()) {
    const AffineRefinement r =
        f->reference.Refine(grey, &warp, &t, options_.affine);
    if (!r.accepted && ++f->failures <= options_.alignment_retries) {
      return done;  // keep the reference: the next frame may match again
    }
    f->failures = 0;
    done.failed = !r.accepted;
    if (r.accepted) {
      done.refined = true;
      f->px = cv::Point2f(t.x(), t.y());
      f->warp = warp;
      const Eigen::JacobiSVD<Eigen::Matrix2f> svd(warp);
      const float limit = static_cast<float>(options_.max_affine_scale);
      keep_reference = svd.singularValues()(0) <= limit &&
                       svd.singularValues()(1) >= 1.0f / limit;
    }
  }
  if (keep_reference) return done;
  // A new reference where the feature is now (frame-to-frame position if
  // the alignment failed).
  // Counted only if a patch was taken: an edge-like or flat one is refused
  // (and tried again next frame), which leaves the feature plain LK.
  f->warp.setIdentity();
  done.reanchored = f->reference.Extract(
      grey, Eigen::Vector2f(f->px.x, f->px.y), options_.affine);
  return done;
}

std::vector<KltFeature> KltTracker::Features() const {
  std::vector<KltFeature> features;
  features.reserve(active_.size());
  for (const Active& a : active_) {
    features.push_back({a.id, Eigen::Vector2d(a.px.x, a.px.y)});
  }
  return features;
}

std::vector<Track> KltTracker::FinishedTracks(int min_length) const {
  std::vector<monomap::Track> result;
  for (const monomap::Track& t : tracks_) {
    if (static_cast<int>(t.observations.size()) >= min_length) {
      result.push_back(t);
    }
  }
  return result;  // tracks_ is indexed by id, hence sorted
}

namespace {

// Feeds frames 0 .. num_frames-1 to `tracker` in order.
void TrackAllFrames(const std::function<cv::Mat(int)>& load_grey,
                    int num_frames, const KltTrackerOptions& options,
                    KltTracker* tracker_ptr) {
  KltTracker& tracker = *tracker_ptr;
  struct Item {
    int frame = 0;
    cv::Mat grey;
    std::vector<cv::Mat> pyramid;
  };
  // Decoding and pyramid building (parallel) overlap with the tracking
  // (serial, in frame order). A few tokens per thread keep the tracker fed
  // without holding many decoded images.
  const size_t max_tokens =
      2 * static_cast<size_t>(tbb::info::default_concurrency()) + 2;
  // Pyramids the tracker is done with go back to the decode stage, which
  // builds into their buffers instead of allocating fresh ones.
  tbb::concurrent_queue<std::vector<cv::Mat>> spares;
  int next = 0;
  tbb::parallel_pipeline(
      max_tokens,
      tbb::make_filter<void, int>(tbb::filter_mode::serial_in_order,
                                  [&](tbb::flow_control& fc) -> int {
                                    if (next >= num_frames) {
                                      fc.stop();
                                      return 0;
                                    }
                                    return next++;
                                  }) &
          tbb::make_filter<int, Item>(
              tbb::filter_mode::parallel,
              [&](int frame) {
                Item item;
                item.frame = frame;
                item.grey = load_grey(frame);
                if (item.grey.empty() || item.grey.type() != CV_8UC1) {
                  throw InputError("frame " + std::to_string(frame) +
                                   ": loader returned no 8-bit grey image");
                }
                std::vector<cv::Mat> recycled;
                if (spares.try_pop(recycled))
                  item.pyramid = std::move(recycled);
                KltTracker::BuildPyramid(item.grey, options, &item.pyramid);
                return item;
              }) &
          tbb::make_filter<Item, void>(
              tbb::filter_mode::serial_in_order, [&](Item item) {
                tracker.Track(item.frame, item.grey, std::move(item.pyramid));
                std::vector<cv::Mat> spare = tracker.ReleaseSparePyramid();
                if (!spare.empty()) spares.push(std::move(spare));
              }));
}

}  // namespace

TrackingReport TrackFeatures(const std::function<cv::Mat(int)>& load_grey,
                             int num_frames, const KltTrackerOptions& options,
                             std::vector<Track>* tracks) {
  options.Check();
  if (num_frames < 1) {
    throw StageError("TrackFeatures: no frames to track");
  }
  Timer timer;
  KltTracker tracker(options);

  TrackAllFrames(load_grey, num_frames, options, &tracker);

  TrackingReport report;
  const KltFrameStats& totals = tracker.TotalStats();
  report.frames = num_frames;
  report.tracks_created = tracker.NumTracksCreated();
  report.lost_forward_backward = totals.lost_forward_backward;
  report.lost_lk = totals.lost_lk + totals.lost_error;
  report.lost_border = totals.lost_border;
  report.refined = totals.refined;
  report.reanchored = totals.reanchored;
  report.split = totals.split;
  report.noise_sigma = tracker.NoiseSigma();
  report.mean_features_per_frame =
      static_cast<double>(totals.total) / num_frames;

  std::vector<Track> result = tracker.FinishedTracks(2);
  report.tracks_returned = static_cast<int64_t>(result.size());
  if (!result.empty()) {
    std::vector<double> lengths;
    lengths.reserve(result.size());
    double sum = 0.0;
    for (const Track& t : result) {
      lengths.push_back(static_cast<double>(t.observations.size()));
      sum += static_cast<double>(t.observations.size());
    }
    report.mean_track_length = sum / static_cast<double>(lengths.size());
    report.median_track_length = Median(std::move(lengths));
  }
  if (tracks != nullptr) *tracks = std::move(result);
  report.seconds = timer.ElapsedSeconds();
  report.frames_per_second =
      report.seconds > 0.0 ? num_frames / report.seconds : 0.0;
  return report;
}

}  // namespace monomap
