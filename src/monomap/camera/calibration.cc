#include "monomap/camera/calibration.h"

#include <tbb/parallel_for.h>

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <string>
#include <vector>

#include "monomap/util/error.h"

namespace monomap {

void CalibrationOptions::Check() const {
  CheckOption(inner_corners_x >= 2 && inner_corners_y >= 2,
              "inner_corners_x/inner_corners_y", "must be >= 2");
  CheckOption(square_m > 0.0, "square_m", "must be > 0");
  CheckOption(stride >= 1, "stride", "must be >= 1");
  CheckOption(min_views >= 3, "min_views", "must be >= 3");
}

namespace {

cv::Matx33d CameraMatrix(const Camera& c) {
  return cv::Matx33d(c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1);
}

// RMS over all corners of `image_points` reprojected from the board.
double RmsError(const std::vector<std::vector<cv::Point3f>>& object_points,
                const std::vector<std::vector<cv::Point2f>>& image_points,
                const cv::Matx33d& k, const std::vector<double>& distortion,
                const std::vector<cv::Mat>* rvecs,
                const std::vector<cv::Mat>* tvecs) {
  double sum = 0.0;
  size_t n = 0;
  for (size_t v = 0; v < image_points.size(); ++v) {
    cv::Mat rvec, tvec;
    if (rvecs != nullptr) {
      rvec = (*rvecs)[v];
      tvec = (*tvecs)[v];
    } else {
      cv::solvePnP(object_points[v], image_points[v], k, distortion, rvec, tvec,
                   false, cv::SOLVEPNP_IPPE);
      cv::solvePnPRefineLM(object_points[v], image_points[v], k, distortion,
                           rvec, tvec);
    }
    std::vector<cv::Point2f> projected;
    cv::projectPoints(object_points[v], rvec, tvec, k, distortion, projected);
    for (size_t i = 0; i < projected.size(); ++i) {
      const cv::Point2f d = projected[i] - image_points[v][i];
      sum += d.dot(d);
      ++n;
    }
  }
  return n > 0 ? std::sqrt(sum / static_cast<double>(n)) : 0.0;
}

}  // namespace

std::optional<std::vector<cv::Point2f>> DetectCheckerboardCorners(
    const cv::Mat& grey, int cols, int rows, int subpix_half_window) {
  std::vector<cv::Point2f> corners;
  if (!cv::findChessboardCorners(
          grey, cv::Size(cols, rows), corners,
          cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE)) {
    return std::nullopt;
  }
  cv::cornerSubPix(
      grey, corners, cv::Size(subpix_half_window, subpix_half_window),
      cv::Size(-1, -1),
      cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50,
                       1e-4));
  return corners;
}

CalibrationReport CalibrateFromCheckerboard(
    const std::function<cv::Mat(int)>& load_grey, int num_frames,
    const Camera& initial, const CalibrationOptions& options) {
  options.Check();
  initial.Check();
  const cv::Size pattern(options.inner_corners_x, options.inner_corners_y);
  std::vector<int> frames;
  for (int i = 0; i < num_frames; i += options.stride) frames.push_back(i);
  std::vector<std::optional<std::vector<cv::Point2f>>> found(frames.size());
  tbb::parallel_for(size_t{0}, frames.size(), [&](size_t k) {
    found[k] = DetectCheckerboardCorners(load_grey(frames[k]), pattern.width,
                                         pattern.height);
  });

  // The board in its own frame; corner order as OpenCV lists it. A view
  // whose listing starts at another corner only flips that view's pose.
  std::vector<cv::Point3f> board;
  for (int j = 0; j < options.inner_corners_y; ++j) {
    for (int i = 0; i < options.inner_corners_x; ++i) {
      board.emplace_back(static_cast<float>(i * options.square_m),
                         static_cast<float>(j * options.square_m), 0.0f);
    }
  }
  CalibrationReport report;
  report.frames_tried = static_cast<int>(frames.size());
  std::vector<std::vector<cv::Point3f>> object_points;
  std::vector<std::vector<cv::Point2f>> image_points;
  for (auto& f : found) {
    if (!f) continue;
    for (const cv::Point2f& p : *f) {
      report.max_corner_radius_px =
          std::max(report.max_corner_radius_px,
                   std::hypot(p.x - initial.cx, p.y - initial.cy));
    }
    object_points.push_back(board);
    image_points.push_back(std::move(*f));
  }
  report.views = static_cast<int>(image_points.size());
  if (report.views < options.min_views) {
    throw StageError("calibration: the " + std::to_string(pattern.width) + "x" +
                     std::to_string(pattern.height) + " board was found in " +
                     std::to_string(report.views) + " of " +
                     std::to_string(report.frames_tried) +
                     " frames (at least " + std::to_string(options.min_views) +
                     " needed)");
  }
  const std::vector<double> initial_distortion(initial.distortion.begin(),
                                               initial.distortion.end());
  report.initial_rms_px =
      RmsError(object_points, image_points, CameraMatrix(initial),
               initial_distortion, nullptr, nullptr);

  cv::Mat k(CameraMatrix(initial));
  cv::Mat distortion(initial_distortion, true);
  int flags = cv::CALIB_USE_INTRINSIC_GUESS;
  if (!options.full_distortion) {
    flags |= cv::CALIB_ZERO_TANGENT_DIST | cv::CALIB_FIX_K3;
  }
  std::vector<cv::Mat> rvecs, tvecs;
  report.final_rms_px = cv::calibrateCamera(
      object_points, image_points, cv::Size(initial.width, initial.height), k,
      distortion, rvecs, tvecs, flags);
  report.camera = initial;
  report.camera.fx = k.at<double>(0, 0);
  report.camera.fy = k.at<double>(1, 1);
  report.camera.cx = k.at<double>(0, 2);
  report.camera.cy = k.at<double>(1, 2);
  for (int i = 0; i < 5; ++i) {
    report.camera.distortion[i] = i < static_cast<int>(distortion.total())
                                      ? distortion.at<double>(i)
                                      : 0.0;
  }
  report.camera.Check();
  return report;
}

}  // namespace monomap
