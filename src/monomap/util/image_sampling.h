// Sub-pixel reads of 8-bit grey images, shared by the tracker's patch
// alignment and plane growth's photometric test.
#pragma once

#include <algorithm>
#include <opencv2/core.hpp>

namespace monomap {

// Bilinear sample of an 8-bit single-channel image at (x, y), for
// 0 <= x <= cols - 1 and 0 <= y <= rows - 1 (the last row and column are
// read as the edge of the cell before them).
inline float SampleGreyBilinear(const cv::Mat& img, float x, float y) {
  const int x0 = std::min(static_cast<int>(x), img.cols - 2);
  const int y0 = std::min(static_cast<int>(y), img.rows - 2);
  const float fx = x - x0, fy = y - y0;
  const uchar* r0 = img.ptr<uchar>(y0) + x0;
  const uchar* r1 = r0 + img.step[0];
  return (1.0f - fy) * ((1.0f - fx) * r0[0] + fx * r0[1]) +
         fy * ((1.0f - fx) * r1[0] + fx * r1[1]);
}

}  // namespace monomap
