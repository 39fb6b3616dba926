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

struct BasinArgs {
  std::string map_dir, dataset_dir, footprint = "area";
  int stride = 10, width = 160, height = 120;
  double mip_bias = RendererOptions().mip_bias;
  bool verbose = false;
  MccOptions mcc;
};

void AddOptions(CLI::App& app, BasinArgs* a) {
  app.add_option("--map", a->map_dir, "Map directory")->required();
  app.add_option("--dataset", a->dataset_dir, "Dataset with ground truth")
      ->required();
  app.add_option("--stride", a->stride, "Every n-th frame");
  app.add_option("--width", a->width, "Correction width");
  app.add_option("--height", a->height, "Correction height");
  app.add_option("--mip-footprint", a->footprint, "area | longest-axis");
  app.add_option("--mip-bias", a->mip_bias, "Renderer mip bias");
  app.add_flag("-v,--verbose", a->verbose, "Print every rejected correction");
  MccOptions& mo = a->mcc;
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
}

struct Offset {
  const char* name;
  Eigen::Vector3d t_cam;  // translation in the camera frame (m)
  double yaw_deg;         // about the world z axis
};

const std::vector<Offset>& Offsets() {
  static const std::vector<Offset> offsets = {
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
  return offsets;
}

// What one offset gave over the frames.
struct OffsetStats {
  int tried = 0, accepted = 0;
  std::vector<double> corners, tracked, inliers, before, after;
};

// The true pose moved by `off`: along the camera's axes, then yawed about
// the world's z.
Rigid3d OffsetPose(const Rigid3d& gt, const Offset& off) {
  Rigid3d start = gt;
  start.translation += gt.rotation * off.t_cam;
  start.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(
                       DegToRadMulDiv(off.yaw_deg), Eigen::Vector3d::UnitZ())) *
                   start.rotation;
  return start;
}

void PrintRejected(const Offset& off, size_t frame, const MccResult& r) {
  std::fprintf(stderr,
               "%s, frame %zu rejected: corners %d tracked %d inliers "
               "%d rms %.2f px, change %.3f m %.2f deg\n",
               off.name, frame, r.corners, r.tracked, r.inliers,
               r.rms_reprojection_px, r.translation_change_m,
               r.rotation_change_deg);
}

OffsetStats MeasureOffset(const BasinArgs& a, const Dataset& dataset,
                          const MonteCarloCorrector& corrector,
                          const LiveImagePreparer& preparer,
                          const Offset& off) {
  OffsetStats s;
  for (size_t i = 0; i < dataset.frames.size(); i += a.stride) {
    const auto& gt = dataset.frames[i].groundtruth_world_from_cam;
    if (!gt) continue;
    const cv::Mat live = LiveImagePreparer::Downscale(
        preparer.Undistort(dataset.LoadImage(i)), a.width, a.height);
    const Rigid3d start = OffsetPose(*gt, off);
    const MccResult r = corrector.Correct(live, start);
    if (!r.accepted && a.verbose) PrintRejected(off, i, r);
    ++s.tried;
    s.accepted += r.accepted;
    s.corners.push_back(r.corners);
    s.tracked.push_back(r.tracked);
    s.inliers.push_back(r.inliers);
    s.before.push_back((start.translation - gt->translation).norm());
    s.after.push_back((r.world_from_cam.translation - gt->translation).norm());
  }
  return s;
}

int Run(int argc, char** argv) {
  CLI::App app{"Basin of one Monte Carlo Correction"};
  BasinArgs a;
  AddOptions(app, &a);
  CLI11_PARSE(app, argc, argv);

  const Map map = ReadMap(a.map_dir);
  const Dataset dataset = LoadDataset(a.dataset_dir);
  RendererOptions ro;
  ro.mip_footprint =
      a.footprint == "area" ? MipFootprint::kArea : MipFootprint::kLongestAxis;
  ro.mip_bias = a.mip_bias;
  const Renderer renderer(map, ro);
  MccOptions mo = a.mcc;
  mo.width = a.width;
  mo.height = a.height;
  const MonteCarloCorrector corrector(&renderer, dataset.camera, mo);
  const LiveImagePreparer preparer(dataset.camera);

  std::printf("%-14s %8s %8s %8s %8s %12s %12s\n", "offset", "accepted",
              "corners", "tracked", "inliers", "err before", "err after");
  for (const Offset& off : Offsets()) {
    const OffsetStats s = MeasureOffset(a, dataset, corrector, preparer, off);
    std::printf("%-14s %7.0f%% %8.0f %8.0f %8.0f %9.1f cm %9.1f cm\n", off.name,
                100.0 * s.accepted / std::max(1, s.tried),
                UpperMedian(s.corners), UpperMedian(s.tracked),
                UpperMedian(s.inliers), 100 * UpperMedian(s.before),
                100 * UpperMedian(s.after));
  }
  return 0;
}

}  // namespace
}  // namespace monomap

int main(int argc, char** argv) { return monomap::Run(argc, argv); }
