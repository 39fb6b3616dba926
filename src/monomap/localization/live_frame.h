// The live image of one filter update, prepared once at every size a
// consumer needs: undistorted, then downscaled (INTER_AREA) to the
// measurement's render size, and, when used, to MCC's and to the estimate
// refinement's.
#pragma once

#include <opencv2/core.hpp>
#include <optional>

#include "monomap/localization/measurement_model.h"

namespace monomap {

// Width and height of an image (px).
struct ImageSize {
  int width = 0;
  int height = 0;
};

// The sizes a Localizer's consumers need (fixed per Localizer).
struct LiveFrameSizes {
  ImageSize measurement;
  std::optional<ImageSize> correction;  // MCC of the particles
  std::optional<ImageSize> refinement;  // MCC of the estimate
};

class LiveFrame {
 public:
  // `raw`: the camera's raw 8-bit image. Throws InputError (via the
  // preparer) if it is not of the camera's size.
  LiveFrame(const cv::Mat& raw, const LiveImagePreparer& preparer,
            const LiveFrameSizes& sizes);

  const cv::Mat& measurement() const { return measurement_; }
  // Empty unless the sizes had a correction (refinement) size.
  const cv::Mat& correction() const { return correction_; }
  const cv::Mat& refinement() const { return refinement_; }

 private:
  cv::Mat measurement_, correction_, refinement_;
};

}  // namespace monomap
