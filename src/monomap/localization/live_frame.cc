#include "monomap/localization/live_frame.h"

namespace monomap {

namespace {

cv::Mat Downscaled(const cv::Mat& undistorted,
                   const std::optional<ImageSize>& size) {
  if (!size) return cv::Mat();
  return LiveImagePreparer::Downscale(undistorted, size->width, size->height);
}

}  // namespace

LiveFrame::LiveFrame(const cv::Mat& raw, const LiveImagePreparer& preparer,
                     const LiveFrameSizes& sizes) {
  const cv::Mat undistorted = preparer.Undistort(raw);
  measurement_ = LiveImagePreparer::Downscale(
      undistorted, sizes.measurement.width, sizes.measurement.height);
  correction_ = Downscaled(undistorted, sizes.correction);
  refinement_ = Downscaled(undistorted, sizes.refinement);
}

}  // namespace monomap
