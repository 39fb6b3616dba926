#include "monomap/eval/render_fidelity.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <opencv2/imgproc.hpp>

#include "monomap/localization/measurement_model.h"
#include "monomap/rendering/renderer.h"
#include "monomap/util/error.h"

namespace monomap {

void RenderFidelityOptions::Check() const {
  CheckOption(width >= 0, "render_fidelity.width", "must be >= 0");
  CheckOption(min_coverage >= 0 && min_coverage <= 1,
              "render_fidelity.min_coverage", "must be in [0, 1]");
}

bool CompareMasked(const cv::Mat& render, const cv::Mat& image,
                   const cv::Mat& mask, double* ncc, double* psnr_db) {
  // Sums over the masked pixels: means, variances, covariance.
  double n = 0, sr = 0, si = 0, srr = 0, sii = 0, sri = 0;
  for (int y = 0; y < render.rows; ++y) {
    const uchar* r = render.ptr<uchar>(y);
    const uchar* im = image.ptr<uchar>(y);
    const uchar* m = mask.ptr<uchar>(y);
    for (int x = 0; x < render.cols; ++x) {
      if (!m[x]) continue;
      const double a = r[x], b = im[x];
      n += 1;
      sr += a;
      si += b;
      srr += a * a;
      sii += b * b;
      sri += a * b;
    }
  }
  if (n < 2) return false;
  const double var_r = srr / n - (sr / n) * (sr / n);
  const double var_i = sii / n - (si / n) * (si / n);
  const double cov = sri / n - (sr / n) * (si / n);
  if (var_r <= 1e-9 || var_i <= 1e-9) return false;
  *ncc = cov / std::sqrt(var_r * var_i);
  // Image ~ gain * render + offset in least squares: the residual variance
  // is var_i (1 - ncc^2).
  const double mse = std::max(var_i * (1.0 - *ncc * *ncc), 1e-12);
  *psnr_db = 10.0 * std::log10(255.0 * 255.0 / mse);
  return true;
}

RenderFidelity EvaluateRenderFidelity(const Map& map, const Camera& camera,
                                      const std::vector<Rigid3d>& world_from_cam,
                                      const std::vector<cv::Mat>& images,
                                      const std::vector<int>& frames,
                                      const RenderFidelityOptions& options) {
  options.Check();
  camera.Check();
  if (world_from_cam.size() != images.size() ||
      frames.size() != images.size()) {
    throw InputError("render fidelity: " + std::to_string(images.size()) +
                     " images for " + std::to_string(world_from_cam.size()) +
                     " poses and " + std::to_string(frames.size()) +
                     " frame indices");
  }
  const Renderer renderer(map);
  const LiveImagePreparer preparer(camera);
  int w = camera.width, h = camera.height;
  if (options.width > 0 && options.width < camera.width) {
    w = options.width;
    h = std::max(1, static_cast<int>(std::lround(
                        static_cast<double>(camera.height) * w / camera.width)));
  }
  const Camera render_camera = preparer.SmallCamera(w, h);

  RenderFidelity result;
  std::vector<double> nccs, psnrs, coverages;
  for (size_t i = 0; i < images.size(); ++i) {
    const cv::Mat& raw = images[i];
    if (raw.cols != camera.width || raw.rows != camera.height ||
        raw.depth() != CV_8U || (raw.channels() != 1 && raw.channels() != 3)) {
      throw InputError("render fidelity: frame " + std::to_string(frames[i]) +
                       ": expected an 8-bit " + std::to_string(camera.width) +
                       "x" + std::to_string(camera.height) + " image");
    }
    const cv::Mat live =
        LiveImagePreparer::Downscale(preparer.Undistort(raw), w, h);
    cv::Mat render, depth;
    renderer.Render(render_camera, world_from_cam[i], &render, &depth);
    const cv::Mat mask = depth > 0.0f;
    FrameFidelity f;
    f.frame = frames[i];
    f.coverage = static_cast<double>(cv::countNonZero(mask)) / (w * h);
    if (f.coverage < options.min_coverage ||
        !CompareMasked(render, live, mask, &f.ncc, &f.psnr_db)) {
      ++result.skipped;
      continue;
    }
    nccs.push_back(f.ncc);
    psnrs.push_back(f.psnr_db);
    coverages.push_back(f.coverage);
    result.frames.push_back(f);
  }
  result.ncc = ComputeErrorStats(nccs);
  result.psnr_db = ComputeErrorStats(psnrs);
  result.coverage = ComputeErrorStats(coverages);
  return result;
}

std::vector<Rigid3d> MovedAlongCameraX(
    const std::vector<Rigid3d>& world_from_cam, double offset_m) {
  std::vector<Rigid3d> moved;
  for (const Rigid3d& p : world_from_cam) {
    moved.push_back(
        p * Rigid3d(Eigen::Quaterniond::Identity(), {offset_m, 0.0, 0.0}));
  }
  return moved;
}

PoseDiscrimination ComparePoses(const RenderFidelity& truth,
                                const RenderFidelity& wrong) {
  PoseDiscrimination d;
  for (const FrameFidelity& a : truth.frames) {
    for (const FrameFidelity& b : wrong.frames) {
      if (b.frame != a.frame) continue;
      ++d.compared;
      d.true_better += a.ncc > b.ncc ? 1 : 0;
    }
  }
  return d;
}

}  // namespace monomap
