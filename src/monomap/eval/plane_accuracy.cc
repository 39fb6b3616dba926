#include "monomap/eval/plane_accuracy.h"

#include <algorithm>

namespace monomap {

namespace {

// Distances at the texel centres the images saw, one every `stride` texels.
std::vector<double> SampleDistances(
    const TexturedPlane& p, int stride,
    const std::function<double(const Eigen::Vector3d&)>& distance) {
  std::vector<double> d;
  for (int r = 0; r < p.texture.rows; r += stride) {
    for (int c = 0; c < p.texture.cols; c += stride) {
      if (p.texture.channels() == 4 && p.texture.at<cv::Vec4b>(r, c)[3] == 0) {
        continue;
      }
      d.push_back(distance(p.WorldFromTexture(Eigen::Vector2d(c, r))));
    }
  }
  return d;
}

}  // namespace

PlaneSurfaceAccuracy EvaluatePlaneSurfaces(
    const Map& map, double spacing_m,
    const std::function<double(const Eigen::Vector3d&)>& distance) {
  PlaneSurfaceAccuracy acc;
  std::vector<double> all;
  for (const TexturedPlane& p : map.planes) {
    const int stride =
        std::max(1, static_cast<int>(spacing_m * p.pixels_per_meter));
    const std::vector<double> d = SampleDistances(p, stride, distance);
    all.insert(all.end(), d.begin(), d.end());
    acc.planes.push_back({p.id, ComputeErrorStats(d)});
  }
  acc.all = ComputeErrorStats(all);
  return acc;
}

}  // namespace monomap
