#include "monomap/texture/mosaic.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <map>
#include <opencv2/imgproc.hpp>
#include <string>
#include <unordered_map>
#include <unordered_set>

#include "monomap/camera/distorted_projector.h"
#include "monomap/util/error.h"
#include "monomap/util/progress.h"
#include "monomap/util/stats.h"

namespace monomap {
namespace {

inline float Luminance(const float* bgr) {
  return 0.114f * bgr[0] + 0.587f * bgr[1] + 0.299f * bgr[2];
}

// Everything needed to sample one frame for one plane.
struct FrameContext {
  int frame = 0;
  const cv::Mat* image = nullptr;  // BGR, 8 bit
  // Segment plane coordinates (s, t, 1) -> undistorted normalized (x, y, 1)
  // (up to scale).
  Eigen::Matrix3d normalized_from_plane;
  Eigen::Vector3d centre;  // camera centre in the world
  float gain = 1.0f;
};

// Geometry of a plane as an occluder.
struct Occluder {
  Plane plane;
  PlaneFrame frame;
  Polygon2d polygon;
  Eigen::Vector2d lo, hi;
};

// Samples the frames of one plane at texture positions.
class PlaneSampler {
 public:
  PlaneSampler(const PlaneSegment& segment, const Eigen::Vector2d& lo,
               double ppm, std::vector<Occluder> occluders,
               const DistortedProjector& projector,
               const MosaicOptions& options)
      : segment_(segment),
        lo_(lo),
        ppm_(ppm),
        occluders_(std::move(occluders)),
        projector_(projector),
        options_(options) {}

  // Segment plane coordinates of texel (c, r).
  Eigen::Vector2d PlaneFromTexel(double c, double r) const {
    return lo_ + Eigen::Vector2d(c + 0.5, r + 0.5) / ppm_;
  }
  bool Inside(const Eigen::Vector2d& st) const {
    return PointInPolygon(segment_.polygon, st);
  }

  // BGR (not gain corrected) of the plane point st seen from `fc`; false if
  // the frame does not see it (outside the image, grazing or occluded).
  bool Sample(const FrameContext& fc, const Eigen::Vector2d& st,
              float* bgr) const {
    const Eigen::Vector3d x = segment_.frame.ToWorld(st);
    const Eigen::Vector3d d = x - fc.centre;
    const double dist = d.norm();
    if (dist <= 0.0) return false;
    if (std::abs(segment_.plane.normal.dot(d)) <
        options_.min_cos_view_angle * dist) {
      return false;
    }
    if (options_.occlusion_test) {
      const double lambda_max = 1.0 - options_.occlusion_margin_m / dist;
      for (const Occluder& o : occluders_) {
        const double denom = o.plane.normal.dot(d);
        if (std::abs(denom) < 1e-12) continue;
        const double lambda = -o.plane.SignedDistance(fc.centre) / denom;
        if (lambda <= 0.0 || lambda >= lambda_max) continue;
        const Eigen::Vector2d q = o.frame.ToPlane(fc.centre + lambda * d);
        if (q.x() < o.lo.x() || q.y() < o.lo.y() || q.x() > o.hi.x() ||
            q.y() > o.hi.y()) {
          continue;
        }
        if (PointInPolygon(o.polygon, q)) return false;
      }
    }
    const Eigen::Vector3d y = fc.normalized_from_plane * st.homogeneous();
    if (y.z() <= 0.0) return false;
    Eigen::Vector2d px;
    if (!projector_.ProjectNormalized(y.hnormalized(), &px)) return false;
    const cv::Mat& img = *fc.image;
    const double m = options_.image_margin_px;
    if (px.x() < m || px.y() < m || px.x() > img.cols - 1 - m ||
        px.y() > img.rows - 1 - m) {
      return false;
    }
    const int x0 = std::min(static_cast<int>(px.x()), img.cols - 2);
    const int y0 = std::min(static_cast<int>(px.y()), img.rows - 2);
    const float ax = static_cast<float>(px.x() - x0);
    const float ay = static_cast<float>(px.y() - y0);
    const uint8_t* r0 = img.ptr<uint8_t>(y0) + 3 * x0;
    const uint8_t* r1 = img.ptr<uint8_t>(y0 + 1) + 3 * x0;
    for (int ch = 0; ch < 3; ++ch) {
      const float top = r0[ch] + ax * (r0[3 + ch] - r0[ch]);
      const float bottom = r1[ch] + ax * (r1[3 + ch] - r1[ch]);
      bgr[ch] = top + ay * (bottom - top);
    }
    return true;
  }

 private:
  const PlaneSegment& segment_;
  Eigen::Vector2d lo_;
  double ppm_;
  std::vector<Occluder> occluders_;
  const DistortedProjector& projector_;
  const MosaicOptions& options_;
};

// Blends n gain-corrected BGR samples (3 floats each) into out[3].
// `scratch` must hold at least n floats.
void Blend(const MosaicOptions& options, float* samples, int n, float* out,
           float* scratch) {
  if (options.blend == BlendMode::kMean || n <= 2) {
    for (int ch = 0; ch < 3; ++ch) {
      float sum = 0.0f;
      for (int i = 0; i < n; ++i) sum += samples[3 * i + ch];
      out[ch] = sum / n;
    }
    return;
  }
  if (options.blend == BlendMode::kMedian) {
    for (int ch = 0; ch < 3; ++ch) {
      for (int i = 0; i < n; ++i) scratch[i] = samples[3 * i + ch];
      out[ch] = MedianInPlace(scratch, scratch + n);
    }
    return;
  }
  // Robust: the median luminance and the MAD decide which samples agree;
  // a moving object or a highlight seen in a minority of frames is far from
  // the median and left out. Averaging the rest keeps the noise low.
  for (int i = 0; i < n; ++i) scratch[i] = Luminance(samples + 3 * i);
  const float median = MedianInPlace(scratch, scratch + n);
  for (int i = 0; i < n; ++i) {
    scratch[i] = std::abs(Luminance(samples + 3 * i) - median);
  }
  const float mad = MedianInPlace(scratch, scratch + n);
  const float band =
      std::max(static_cast<float>(options.robust_mad_k * 1.4826) * mad,
               static_cast<float>(options.robust_min_band));
  float sum[3] = {0, 0, 0};
  int count = 0;
  for (int i = 0; i < n; ++i) {
    if (std::abs(Luminance(samples + 3 * i) - median) > band) continue;
    for (int ch = 0; ch < 3; ++ch) sum[ch] += samples[3 * i + ch];
    ++count;
  }
  if (count == 0) {  // cannot happen (the median sample is in), but be safe
    for (int ch = 0; ch < 3; ++ch) out[ch] = samples[ch];
    return;
  }
  for (int ch = 0; ch < 3; ++ch) out[ch] = sum[ch] / count;
}

// Per-frame gains bringing each frame's exposure to the common one: the
// median over texels of (median sample of the texel / sample of the frame),
// robust to moving objects and highlights. Two rounds, normalised to a
// geometric mean of 1.
void EstimateGains(const PlaneSampler& sampler, int width, int height,
                   int num_samples, std::vector<FrameContext>* frames) {
  const int nf = static_cast<int>(frames->size());
  if (nf < 2) return;
  const double step = std::max(
      1.0, std::sqrt(static_cast<double>(width) * height / num_samples));
  std::vector<Eigen::Vector2d> points;
  for (double r = 0.5 * step; r < height; r += step) {
    for (double c = 0.5 * step; c < width; c += step) {
      const Eigen::Vector2d st = sampler.PlaneFromTexel(std::floor(c),
                                                        std::floor(r));
      if (sampler.Inside(st)) points.push_back(st);
    }
  }
  const int np = static_cast<int>(points.size());
  if (np == 0) return;
  // Luminance per (point, frame); negative = not seen.
  std::vector<float> lum(static_cast<size_t>(np) * nf, -1.0f);
  tbb::parallel_for(0, np, [&](int i) {
    float bgr[3];
    for (int f = 0; f < nf; ++f) {
      if (sampler.Sample((*frames)[f], points[i], bgr)) {
        lum[static_cast<size_t>(i) * nf + f] = Luminance(bgr);
      }
    }
  });
  std::vector<float> gains(nf, 1.0f);
  constexpr float kMinLevel = 8.0f;  // ratios of near-black are noise
  for (int round = 0; round < 2; ++round) {
    std::vector<float> reference(np, -1.0f);
    std::vector<float> tmp;
    for (int i = 0; i < np; ++i) {
      tmp.clear();
      for (int f = 0; f < nf; ++f) {
        const float l = lum[static_cast<size_t>(i) * nf + f];
        if (l >= 0) tmp.push_back(l * gains[f]);
      }
      if (tmp.size() >= 2) {
        reference[i] = MedianInPlace(tmp.data(), tmp.data() + tmp.size());
      }
    }
    std::vector<float> new_gains(nf, 1.0f);
    double log_sum = 0.0;
    int num_log = 0;
    for (int f = 0; f < nf; ++f) {
      tmp.clear();
      for (int i = 0; i < np; ++i) {
        const float l = lum[static_cast<size_t>(i) * nf + f];
        if (l >= kMinLevel && reference[i] >= kMinLevel) {
          tmp.push_back(reference[i] / l);
        }
      }
      if (tmp.size() >= 10) {
        new_gains[f] = MedianInPlace(tmp.data(), tmp.data() + tmp.size());
        log_sum += std::log(new_gains[f]);
        ++num_log;
      }
    }
    const float norm =
        num_log > 0 ? static_cast<float>(std::exp(-log_sum / num_log)) : 1.0f;
    for (int f = 0; f < nf; ++f) gains[f] = new_gains[f] * norm;
  }
  for (int f = 0; f < nf; ++f) (*frames)[f].gain = gains[f];
}

std::vector<FeatureId> PlaneFeatureIds(const PlaneSegment& seg,
                                       const std::vector<Landmark>& landmarks) {
  std::unordered_set<FeatureId> ids(seg.inlier_ids.begin(),
                                    seg.inlier_ids.end());
  for (const auto& l : landmarks) {
    if (l.plane_id == seg.id) ids.insert(l.id);
  }
  std::vector<FeatureId> sorted(ids.begin(), ids.end());
  std::sort(sorted.begin(), sorted.end());
  return sorted;
}

// Frames blended for a plane: the candidates split into `max_frames`
// consecutive groups, the best view of each group (visible fraction x
// resolution: closer and more frontal is better).
std::vector<const ImagePlaneHomography*> SelectFrames(
    std::vector<const ImagePlaneHomography*> candidates, int max_frames) {
  std::sort(candidates.begin(), candidates.end(),
            [](const auto* a, const auto* b) { return a->frame < b->frame; });
  const int n = static_cast<int>(candidates.size());
  if (n <= max_frames) return candidates;
  std::vector<const ImagePlaneHomography*> selected;
  for (int g = 0; g < max_frames; ++g) {
    const int begin = static_cast<int>(static_cast<int64_t>(g) * n / max_frames);
    const int end =
        static_cast<int>(static_cast<int64_t>(g + 1) * n / max_frames);
    const ImagePlaneHomography* best = nullptr;
    double best_score = -1.0;
    for (int i = begin; i < end; ++i) {
      const double score =
          candidates[i]->visible_fraction * candidates[i]->pixels_per_meter;
      if (score > best_score) {
        best_score = score;
        best = candidates[i];
      }
    }
    if (best != nullptr) selected.push_back(best);
  }
  return selected;
}

cv::Mat ToBgr(const cv::Mat& image, int frame, const Camera& camera) {
  if (image.empty()) {
    throw InputError("image of frame " + std::to_string(frame) +
                     " is empty");
  }
  if (image.cols != camera.width || image.rows != camera.height) {
    throw InputError("image of frame " + std::to_string(frame) + " is " +
                     std::to_string(image.cols) + "x" +
                     std::to_string(image.rows) + ", the camera expects " +
                     std::to_string(camera.width) + "x" +
                     std::to_string(camera.height));
  }
  if (image.depth() != CV_8U ||
      (image.channels() != 1 && image.channels() != 3)) {
    throw InputError("image of frame " + std::to_string(frame) +
                     " is not 8-bit grey or BGR");
  }
  if (image.channels() == 3) return image;
  cv::Mat bgr;
  cv::cvtColor(image, bgr, cv::COLOR_GRAY2BGR);
  return bgr;
}

}  // namespace

void MosaicOptions::Check() const {
  CheckOption(pixels_per_meter >= 0.0, "mosaic.pixels_per_meter",
              "must be >= 0 (0 = automatic)");
  CheckOption(max_pixels_per_meter > 0.0, "mosaic.max_pixels_per_meter",
              "must be > 0");
  CheckOption(max_texture_side >= 1, "mosaic.max_texture_side",
              "must be >= 1");
  CheckOption(max_frames_per_plane >= 1, "mosaic.max_frames_per_plane",
              "must be >= 1");
  CheckOption(robust_mad_k > 0.0, "mosaic.robust_mad_k", "must be > 0");
  CheckOption(robust_min_band >= 0.0, "mosaic.robust_min_band",
              "must be >= 0");
  CheckOption(gain_samples >= 10, "mosaic.gain_samples", "must be >= 10");
  CheckOption(min_cos_view_angle >= 0.0 && min_cos_view_angle < 1.0,
              "mosaic.min_cos_view_angle", "must be in [0, 1)");
  CheckOption(occlusion_margin_m >= 0.0, "mosaic.occlusion_margin_m",
              "must be >= 0");
  CheckOption(image_margin_px >= 0.0, "mosaic.image_margin_px",
              "must be >= 0");
}

namespace {

// Texels per metre of a plane's texture: the option, or the median
// resolution of its selected views; capped so no side exceeds
// max_texture_side.
double TexturePixelsPerMeter(
    const std::vector<const ImagePlaneHomography*>& selected,
    const Eigen::Vector2d& extent, const MosaicOptions& options) {
  double ppm = options.pixels_per_meter;
  if (ppm <= 0.0) {
    std::vector<double> res;
    for (const auto* h : selected) {
      if (h->pixels_per_meter > 0) res.push_back(h->pixels_per_meter);
    }
    ppm = res.empty() ? options.max_pixels_per_meter : Median(res);
    ppm = std::min(ppm, options.max_pixels_per_meter);
  }
  return std::min(ppm, options.max_texture_side / extent.maxCoeff());
}

// Keeps the cached images this plane's views need and loads the others.
void LoadViewImages(const std::vector<const ImagePlaneHomography*>& selected,
                    const ImageLoader& load_image, const Camera& camera,
                    std::map<int, cv::Mat>* cache) {
  std::unordered_set<int> needed;
  for (const auto* h : selected) needed.insert(h->frame);
  for (auto it = cache->begin(); it != cache->end();) {
    it = needed.count(it->first) ? std::next(it) : cache->erase(it);
  }
  // Decoding dominates the loading: load in parallel. The loader reads
  // files and keeps no state.
  std::vector<int> missing;
  for (const auto* h : selected) {
    if (!cache->count(h->frame)) missing.push_back(h->frame);
  }
  std::vector<cv::Mat> loaded(missing.size());
  tbb::parallel_for(size_t{0}, missing.size(), [&](size_t i) {
    loaded[i] = ToBgr(load_image(missing[i]), missing[i], camera);
  });
  for (size_t i = 0; i < missing.size(); ++i) {
    (*cache)[missing[i]] = std::move(loaded[i]);
  }
}

// The blended texture (BGRA, alpha 0 where no view saw the plane).
// Coverage counts go to *inside (texels inside the polygon) and *seen.
cv::Mat BlendTexture(const PlaneSampler& sampler,
                     const std::vector<FrameContext>& frames, int width,
                     int height, const MosaicOptions& options, int* inside,
                     int* seen) {
  // Rows are independent: sample all frames for a row and blend it, so
  // memory stays at one row of samples per thread.
  cv::Mat texture(height, width, CV_8UC4, cv::Scalar(0, 0, 0, 0));
  std::vector<int> inside_per_row(height, 0), seen_per_row(height, 0);
  const int nf = static_cast<int>(frames.size());
  tbb::parallel_for(
      tbb::blocked_range<int>(0, height, 4),
      [&](const tbb::blocked_range<int>& range) {
        std::vector<float> samples(3 * nf), scratch(nf);
        for (int r = range.begin(); r < range.end(); ++r) {
          cv::Vec4b* out = texture.ptr<cv::Vec4b>(r);
          for (int c = 0; c < width; ++c) {
            const Eigen::Vector2d st = sampler.PlaneFromTexel(c, r);
            if (!sampler.Inside(st)) continue;
            ++inside_per_row[r];
            int n = 0;
            for (int f = 0; f < nf; ++f) {
              float* s = samples.data() + 3 * n;
              if (sampler.Sample(frames[f], st, s)) {
                for (int ch = 0; ch < 3; ++ch) s[ch] *= frames[f].gain;
                ++n;
              }
            }
            if (n == 0) continue;
            float bgr[3];
            Blend(options, samples.data(), n, bgr, scratch.data());
            for (int ch = 0; ch < 3; ++ch) {
              out[c][ch] = cv::saturate_cast<uint8_t>(bgr[ch]);
            }
            out[c][3] = 255;
            ++seen_per_row[r];
          }
        }
      });
  *inside = 0;
  *seen = 0;
  for (int r = 0; r < height; ++r) {
    *inside += inside_per_row[r];
    *seen += seen_per_row[r];
  }
  return texture;
}

// The plane's features (tp->features) and, for each, the distance (texture
// px) between it and the median of its observations mapped into the
// texture by every view of the plane (not only the blended ones: more
// observations, a better median).
std::vector<double> AddPlaneFeatures(
    const Camera& camera, const PlaneSegment& seg, const Eigen::Vector2d& lo,
    const std::vector<const ImagePlaneHomography*>& views,
    const std::vector<Landmark>& landmarks,
    const std::unordered_map<FeatureId, const Track*>& track_by_id,
    const std::unordered_map<FeatureId, const Landmark*>& landmark_by_id,
    TexturedPlane* tp) {
  std::unordered_map<int, Eigen::Matrix3d> plane_from_pixel;
  for (const auto* h : views) {
    plane_from_pixel[h->frame] = h->pixel_from_plane.inverse();
  }
  const double ppm = tp->pixels_per_meter;
  std::vector<double> residuals;
  for (FeatureId id : PlaneFeatureIds(seg, landmarks)) {
    const auto lit = landmark_by_id.find(id);
    if (lit == landmark_by_id.end()) continue;
    PlaneFeature pf;
    pf.id = id;
    pf.x_in_world = lit->second->x_in_world;
    pf.texture_px = tp->TextureFromWorld(seg.plane.Project(pf.x_in_world));
    tp->features.push_back(pf);
    const auto tit = track_by_id.find(id);
    if (tit == track_by_id.end()) continue;
    std::vector<double> xs, ys;
    for (const Observation& o : tit->second->observations) {
      const auto hit = plane_from_pixel.find(o.frame);
      if (hit == plane_from_pixel.end()) continue;
      const Eigen::Vector3d y =
          hit->second * UndistortedPixel(camera, o.px).homogeneous();
      if (std::abs(y.z()) < 1e-12) continue;
      const Eigen::Vector2d tex =
          (y.hnormalized() - lo) * ppm - Eigen::Vector2d(0.5, 0.5);
      xs.push_back(tex.x());
      ys.push_back(tex.y());
    }
    if (xs.empty()) continue;
    residuals.push_back(
        (Eigen::Vector2d(Median(xs), Median(ys)) - pf.texture_px).norm());
  }
  return residuals;
}

void SetFeatureResidualStats(const std::vector<double>& residuals,
                             PlaneMosaicStats* stats) {
  stats->num_features = static_cast<int>(residuals.size());
  if (residuals.empty()) return;
  double sum = 0.0;
  for (double r : residuals) {
    sum += r;
    stats->feature_residual_max_px =
        std::max(stats->feature_residual_max_px, r);
  }
  stats->feature_residual_mean_px = sum / residuals.size();
  stats->feature_residual_median_px = Median(residuals);
}

// What every plane's mosaic needs: the inputs, indexed, and the other
// planes as occluders.
struct MosaicInputs {
  const Camera& camera;
  const std::vector<Rigid3d>& world_from_cam;
  const std::vector<PlaneSegment>& segments;
  const std::vector<Landmark>& landmarks;
  const ImageLoader& load_image;
  const MosaicOptions& options;
  std::unordered_map<FeatureId, const Track*> track_by_id;
  std::unordered_map<FeatureId, const Landmark*> landmark_by_id;
  std::vector<Occluder> all_occluders;
  const DistortedProjector projector;
  const Eigen::Matrix3d k_inv;
};

// The textured plane of segments[p] from its selected views (all_views:
// every view, for the feature residuals); images come through *cache.
TexturedPlane BuildTexturedPlane(
    const MosaicInputs& in, int p,
    const std::vector<const ImagePlaneHomography*>& selected,
    const std::vector<const ImagePlaneHomography*>& all_views,
    std::map<int, cv::Mat>* cache, PlaneMosaicStats* stats) {
  const PlaneSegment& seg = in.segments[p];
  Eigen::Vector2d lo, hi;
  PolygonBounds(seg.polygon, &lo, &hi);
  const Eigen::Vector2d extent = (hi - lo).cwiseMax(1e-6);
  const double ppm = TexturePixelsPerMeter(selected, extent, in.options);
  const int side = in.options.max_texture_side;
  const int width =
      std::clamp(static_cast<int>(std::ceil(extent.x() * ppm)), 1, side);
  const int height =
      std::clamp(static_cast<int>(std::ceil(extent.y() * ppm)), 1, side);
  LoadViewImages(selected, in.load_image, in.camera, cache);
  std::vector<FrameContext> frames;
  for (const auto* h : selected) {
    FrameContext fc;
    fc.frame = h->frame;
    fc.image = &(*cache)[h->frame];
    fc.normalized_from_plane = in.k_inv * h->pixel_from_plane;
    fc.centre = in.world_from_cam[h->frame].translation;
    frames.push_back(fc);
  }
  std::vector<Occluder> occluders;
  for (int q = 0; q < static_cast<int>(in.segments.size()); ++q) {
    if (q != p && in.all_occluders[q].polygon.size() >= 3) {
      occluders.push_back(in.all_occluders[q]);
    }
  }
  const PlaneSampler sampler(seg, lo, ppm, std::move(occluders), in.projector,
                             in.options);
  if (in.options.gain_compensation) {
    EstimateGains(sampler, width, height, in.options.gain_samples, &frames);
  }
  int inside = 0, seen = 0;
  TexturedPlane tp;
  tp.id = seg.id;
  tp.plane = seg.plane;
  tp.frame = seg.frame;
  tp.frame.origin = seg.frame.ToWorld(lo);
  tp.pixels_per_meter = ppm;
  tp.texture =
      BlendTexture(sampler, frames, width, height, in.options, &inside, &seen);
  for (const auto& v : seg.polygon) tp.polygon.push_back(v - lo);
  for (const auto& v : seg.landmark_polygon) {
    tp.landmark_polygon.push_back(v - lo);
  }
  const std::vector<double> residuals =
      AddPlaneFeatures(in.camera, seg, lo, all_views, in.landmarks,
                       in.track_by_id, in.landmark_by_id, &tp);
  stats->plane_id = seg.id;
  stats->pixels_per_meter = ppm;
  stats->width = width;
  stats->height = height;
  for (const auto& fc : frames) stats->frames.push_back(fc.frame);
  stats->coverage = inside > 0 ? static_cast<double>(seen) / inside : 0.0;
  SetFeatureResidualStats(residuals, stats);
  return tp;
}

}  // namespace

MosaicReport BuildTexturedPlanes(
    const Camera& camera, const std::vector<Rigid3d>& world_from_cam,
    const std::vector<PlaneSegment>& segments,
    const std::vector<Landmark>& landmarks, const std::vector<Track>& tracks,
    const std::vector<ImagePlaneHomography>& homographies,
    const ImageLoader& load_image, const MosaicOptions& options,
    std::vector<TexturedPlane>* planes) {
  options.Check();
  camera.Check();
  Timer timer;
  MosaicReport report;
  planes->clear();
  const int num_frames = static_cast<int>(world_from_cam.size());
  const int num_planes = static_cast<int>(segments.size());
  MosaicInputs in{camera,  world_from_cam, segments,
                  landmarks, load_image,   options,
                  {},      {},             std::vector<Occluder>(num_planes),
                  DistortedProjector(camera), camera.K().inverse()};
  for (const auto& t : tracks) in.track_by_id[t.id] = &t;
  for (const auto& l : landmarks) in.landmark_by_id[l.id] = &l;
  for (int p = 0; p < num_planes; ++p) {
    Occluder& o = in.all_occluders[p];
    o.plane = segments[p].plane;
    o.frame = segments[p].frame;
    o.polygon = segments[p].polygon;
    if (o.polygon.size() >= 3) PolygonBounds(o.polygon, &o.lo, &o.hi);
  }

  // Frame selection for every plane first, so that images are loaded once
  // for consecutive planes sharing frames.
  std::vector<std::vector<const ImagePlaneHomography*>> all_views(num_planes);
  std::vector<std::vector<const ImagePlaneHomography*>> selected(num_planes);
  for (int p = 0; p < num_planes; ++p) {
    if (segments[p].polygon.size() < 3) continue;
    for (const auto& h : homographies) {
      if (h.plane_id == segments[p].id && h.frame >= 0 &&
          h.frame < num_frames) {
        all_views[p].push_back(&h);
      }
    }
    selected[p] = SelectFrames(all_views[p], options.max_frames_per_plane);
  }

  std::map<int, cv::Mat> cache;
  for (int p = 0; p < num_planes; ++p) {
    if (selected[p].empty()) {
      ++report.num_planes_skipped;
      continue;
    }
    PlaneMosaicStats stats;
    planes->push_back(
        BuildTexturedPlane(in, p, selected[p], all_views[p], &cache, &stats));
    report.planes.push_back(stats);
  }
  report.seconds = timer.ElapsedSeconds();
  return report;
}

}  // namespace monomap
