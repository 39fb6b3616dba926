#include "monomap/localization/measurement_model.h"

#include <cmath>

#include <opencv2/imgproc.hpp>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "monomap/util/error.h"

namespace monomap {

LiveImagePreparer::LiveImagePreparer(const Camera& camera) : camera_(camera) {
  camera_.Check();
  if (!camera_.HasDistortion()) return;
  map_x_.create(camera_.height, camera_.width, CV_32FC1);
  map_y_.create(camera_.height, camera_.width, CV_32FC1);
  for (int v = 0; v < camera_.height; ++v) {
    for (int u = 0; u < camera_.width; ++u) {
      // Pinhole pixel -> ray -> raw pixel where that ray was imaged.
      const Eigen::Vector3d ray((u - camera_.cx) / camera_.fx,
                                (v - camera_.cy) / camera_.fy, 1.0);
      const Eigen::Vector2d raw = camera_.ImageFromCam(ray);
      map_x_.at<float>(v, u) = static_cast<float>(raw.x());
      map_y_.at<float>(v, u) = static_cast<float>(raw.y());
    }
  }
  // The fixed-point form cv::remap converts float maps to on every call
  // (same pixels, without the conversion per frame).
  cv::convertMaps(map_x_, map_y_, map_xy_, map_frac_, CV_16SC2);
}

cv::Mat LiveImagePreparer::Undistort(const cv::Mat& raw) const {
  if (raw.empty() || raw.depth() != CV_8U) {
    throw InputError("live image: need a non-empty 8-bit image");
  }
  if (raw.cols != camera_.width || raw.rows != camera_.height) {
    throw InputError("live image: size " + std::to_string(raw.cols) + "x" +
                     std::to_string(raw.rows) + " differs from the camera's " +
                     std::to_string(camera_.width) + "x" +
                     std::to_string(camera_.height));
  }
  cv::Mat grey;
  if (raw.channels() == 3) {
    cv::cvtColor(raw, grey, cv::COLOR_BGR2GRAY);
  } else if (raw.channels() == 4) {
    cv::cvtColor(raw, grey, cv::COLOR_BGRA2GRAY);
  } else {
    grey = raw;
  }
  if (map_x_.empty()) return grey.clone();
  cv::Mat out;
  cv::remap(grey, out, map_xy_, map_frac_, cv::INTER_LINEAR,
            cv::BORDER_REPLICATE);
  return out;
}

cv::Mat LiveImagePreparer::Downscale(const cv::Mat& undistorted, int width,
                                     int height) {
  if (undistorted.cols == width && undistorted.rows == height) {
    return undistorted.clone();
  }
  cv::Mat out;
  cv::resize(undistorted, out, cv::Size(width, height), 0, 0, cv::INTER_AREA);
  return out;
}

void MeasurementOptions::Check() const {
  CheckOption(width >= 8 && height >= 8, "measurement.width/height",
              "must be >= 8");
  CheckOption(sigma > 0, "measurement.sigma", "must be > 0");
  CheckOption(min_coverage >= 0 && min_coverage <= 1,
              "measurement.min_coverage", "must be in [0, 1]");
  CheckOption(min_pixels >= 2, "measurement.min_pixels", "must be >= 2");
}

MeasurementModel::MeasurementModel(const Renderer* renderer,
                                   const Camera& camera,
                                   const MeasurementOptions& options)
    : renderer_(renderer), preparer_(camera), options_(options) {
  options_.Check();
  if (renderer_ == nullptr) throw OptionsError("measurement: null renderer");
  render_camera_ = preparer_.SmallCamera(options_.width, options_.height);
}

cv::Mat MeasurementModel::PrepareLive(const cv::Mat& raw) const {
  return PrepareLiveFromUndistorted(preparer_.Undistort(raw));
}

cv::Mat MeasurementModel::PrepareLiveFromUndistorted(
    const cv::Mat& undistorted) const {
  return LiveImagePreparer::Downscale(undistorted, options_.width,
                                      options_.height);
}

void MeasurementModel::Ncc(const cv::Mat& render, const cv::Mat& depth,
                           const cv::Mat& live, int min_pixels, double* ncc,
                           double* coverage) {
  // One pass of integer sums: exact and fast for 8-bit images.
  int64_t n = 0, sr = 0, sl = 0, srr = 0, sll = 0, srl = 0;
  for (int y = 0; y < render.rows; ++y) {
    const uint8_t* r = render.ptr<uint8_t>(y);
    const float* d = depth.ptr<float>(y);
    const uint8_t* l = live.ptr<uint8_t>(y);
    for (int x = 0; x < render.cols; ++x) {
      if (!(d[x] > 0.0f)) continue;
      const int a = r[x], b = l[x];
      ++n;
      sr += a;
      sl += b;
      srr += a * a;
      sll += b * b;
      srl += a * b;
    }
  }
  *coverage = static_cast<double>(n) / (render.rows * render.cols);
  *ncc = 0.0;
  if (n < min_pixels) return;
  const double dn = static_cast<double>(n);
  const double var_r = srr - static_cast<double>(sr) * sr / dn;
  const double var_l = sll - static_cast<double>(sl) * sl / dn;
  const double cov = srl - static_cast<double>(sr) * sl / dn;
  // Flat patches carry no information either way.
  if (var_r < dn * 1.0 || var_l < dn * 1.0) return;
  *ncc = cov / std::sqrt(var_r * var_l);
}

double MeasurementModel::LogLikelihood(double ncc, double coverage) const {
  double effective = ncc;
  if (coverage < options_.min_coverage && options_.min_coverage > 0) {
    effective *= coverage / options_.min_coverage;
  }
  return (effective - 1.0) / options_.sigma;
}

MeasurementScore MeasurementModel::Score(const cv::Mat& live_small,
                                         const Rigid3d& pose) const {
  cv::Mat grey, depth;
  renderer_->Render(render_camera_, pose, &grey, &depth);
  MeasurementScore s;
  Ncc(grey, depth, live_small, options_.min_pixels, &s.ncc, &s.coverage);
  s.log_likelihood = LogLikelihood(s.ncc, s.coverage);
  return s;
}

std::vector<MeasurementScore> MeasurementModel::ScoreBatch(
    const cv::Mat& live_small, const std::vector<Rigid3d>& poses) const {
  if (live_small.cols != options_.width || live_small.rows != options_.height ||
      live_small.type() != CV_8UC1) {
    throw InputError("measurement: live image must be 8-bit grey " +
                     std::to_string(options_.width) + "x" +
                     std::to_string(options_.height));
  }
  std::vector<MeasurementScore> scores(poses.size());
  // Render buffers per thread: no allocation per particle.
  struct Buffers {
    cv::Mat grey, depth;
  };
  tbb::enumerable_thread_specific<Buffers> buffers;
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, poses.size(), 8),
      [&](const tbb::blocked_range<size_t>& range) {
        Buffers& b = buffers.local();
        for (size_t i = range.begin(); i != range.end(); ++i) {
          renderer_->Render(render_camera_, poses[i], &b.grey, &b.depth);
          MeasurementScore& s = scores[i];
          Ncc(b.grey, b.depth, live_small, options_.min_pixels, &s.ncc,
              &s.coverage);
          s.log_likelihood = LogLikelihood(s.ncc, s.coverage);
        }
      });
  return scores;
}

}  // namespace monomap
