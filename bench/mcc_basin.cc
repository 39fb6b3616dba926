// The basin of one Monte Carlo Correction: from poses offset from the
// ground truth by known amounts, how often does MonteCarloCorrector land
// near the truth? This is what decides whether MCC can pull particles of
// the right neighbourhood onto the true pose.
//
//   build/bench/mcc_basin --map MAP_DIR --dataset DATASET [--stride 10]
//
// The MCC and renderer options can be set to compare variants (--help).
//
// For every stride-th frame with ground truth and each offset (along the
// camera's x and z axes and yaw about the world's z, on both sides) one
// correction is run; reported per offset: accepted fraction, median
// corners, tracked corners and inliers, and the median error after the
// correction (all attempts; rejected ones keep their offset).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "monomap/io/dataset.h"
#include "monomap/io/map_format.h"
#include "monomap/localization/mcc.h"
#include "monomap/localization/measurement_model.h"
#include "monomap/rendering/renderer.h"
#include "monomap/util/angles.h"
#include "monomap/util/stats.h"

namespace monomap {
namespace {

int Run(int argc, char** argv) {
  CLI::App app{"Basin of one Monte Carlo Correction"};
  std::string map_dir, dataset_dir, footprint = "area";
  int stride = 10, width = 160, height = 120;
  app.add_option("--map", map_dir, "Map directory")->required();
  app.add_option("--dataset", dataset_dir, "Dataset with ground truth")
      ->required();
  app.add_option("--stride", stride, "Every n-th frame");
  app.add_option("--width", width, "Correction width");
  app.add_option("--height", height, "Correction height");
  app.add_option("--mip-footprint", footprint, "area | longest-axis");
  double mip_bias = RendererOptions().mip_bias;
  app.add_option("--mip-bias", mip_bias, "Renderer mip bias");
  bool verbose = false;
  app.add_flag("-v,--verbose", verbose, "Print every rejected correction");
  MccOptions mo;
  app.add_option("--max-fb", mo.max_forward_backward_px,
                 "Forward-backward KLT limit (px)");
  app.add_option("--iterations", mo.iterations, "Render-track-solve rounds");
  app.add_option("--klt-window", mo.klt_window, "KLT window (px)");
  app.add_option("--klt-levels", mo.klt_levels, "KLT pyramid levels");
  app.add_option("--ransac-threshold", mo.ransac_threshold_px,
                 "PnP inlier threshold (px)");
  app.add_option("--extra-mip-bias", mo.extra_mip_bias,
                 "Mip bias MCC adds to the renderer's");
  app.add_option("--max-translation", mo.max_translation_m,
                 "Largest accepted correction (m)");
  CLI11_PARSE(app, argc, argv);

  const Map map = ReadMap(map_dir);
  const Dataset dataset = LoadDataset(dataset_dir);
  RendererOptions ro;
  ro.mip_footprint =
      footprint == "area" ? MipFootprint::kArea : MipFootprint::kLongestAxis;
  ro.mip_bias = mip_bias;
  const Renderer renderer(map, ro);
  mo.width = width;
  mo.height = height;
  const MonteCarloCorrector corrector(&renderer, dataset.camera, mo);
  const LiveImagePreparer preparer(dataset.camera);

  struct Offset {
    const char* name;
    Eigen::Vector3d t_cam;  // translation in the camera frame (m)
    double yaw_deg;         // about the world z axis
  };
  const std::vector<Offset> offsets = {
      {"none", {0, 0, 0}, 0},
      {"x 5 cm", {0.05, 0, 0}, 0},
      {"x -5 cm", {-0.05, 0, 0}, 0},
      {"z 10 cm", {0, 0, 0.10}, 0},
      {"z -10 cm", {0, 0, -0.10}, 0},
      {"z -20 cm", {0, 0, -0.20}, 0},
      {"yaw 3 deg", {0, 0, 0}, 3},
      {"yaw -3 deg", {0, 0, 0}, -3},
      {"x 10 cm yaw 3", {0.10, 0, 0}, 3},
      {"x 20 cm", {0.20, 0, 0}, 0},
      {"z -30 cm", {0, 0, -0.30}, 0},
      {"yaw 6 deg", {0, 0, 0}, 6},
  };
  std::printf("%-14s %8s %8s %8s %8s %12s %12s\n", "offset", "accepted",
              "corners", "tracked", "inliers", "err before", "err after");
  for (const Offset& off : offsets) {
    int tried = 0, accepted = 0;
    std::vector<double> corners, tracked, inliers, before, after;
    for (size_t i = 0; i < dataset.frames.size(); i += stride) {
      const auto& gt = dataset.frames[i].groundtruth_world_from_cam;
      if (!gt) continue;
      const cv::Mat live = LiveImagePreparer::Downscale(
          preparer.Undistort(dataset.LoadImage(i)), width, height);
      Rigid3d start = *gt;
      start.translation += gt->rotation * off.t_cam;
      start.rotation =
          Eigen::Quaterniond(Eigen::AngleAxisd(DegToRadMulDiv(off.yaw_deg),
                                               Eigen::Vector3d::UnitZ())) *
          start.rotation;
      const MccResult r = corrector.Correct(live, start);
      if (!r.accepted && verbose) {
        std::fprintf(stderr,
                     "%s, frame %zu rejected: corners %d tracked %d inliers "
                     "%d rms %.2f px, change %.3f m %.2f deg\n",
                     off.name, i, r.corners, r.tracked, r.inliers,
                     r.rms_reprojection_px, r.translation_change_m,
                     r.rotation_change_deg);
      }
      ++tried;
      accepted += r.accepted;
      corners.push_back(r.corners);
      tracked.push_back(r.tracked);
      inliers.push_back(r.inliers);
      before.push_back((start.translation - gt->translation).norm());
      after.push_back((r.world_from_cam.translation - gt->translation).norm());
    }
    std::printf("%-14s %7.0f%% %8.0f %8.0f %8.0f %9.1f cm %9.1f cm\n", off.name,
                100.0 * accepted / std::max(1, tried), UpperMedian(corners),
                UpperMedian(tracked), UpperMedian(inliers),
                100 * UpperMedian(before), 100 * UpperMedian(after));
  }
  return 0;
}

}  // namespace
}  // namespace monomap

int main(int argc, char** argv) { return monomap::Run(argc, argv); }
