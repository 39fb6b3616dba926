// The shape of MCL's measurement likelihood around the true pose: for
// every stride-th frame with ground truth, the pose is moved along one
// axis (the camera's x and z, yaw about the world's z) and each moved pose
// is scored as a particle would be (render, NCC, log-likelihood). Summed
// over the frames, the profile shows where the likelihood peaks (a peak
// off zero is a bias no particle filter can remove) and how sharp it is
// (how many log units one offset costs).
//
//   build/bench/likelihood_profile --map MAP_DIR --dataset DATASET
//       [--stride 5] [--width 80 --height 60] [--sigma 0.05]
//
// Prints, per axis and offset, the mean over frames of
// log L(offset) - log L(0), and per axis the median over frames of the
// offset where each frame's profile peaks.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "monomap/io/dataset.h"
#include "monomap/io/map_format.h"
#include "monomap/localization/measurement_model.h"
#include "monomap/rendering/renderer.h"
#include "monomap/util/angles.h"
#include "monomap/util/stats.h"
#include "sweep_main.h"

namespace monomap {
namespace {

struct Axis {
  const char* name;
  const char* unit;
  double step;  // offset between samples
  // The pose moved by `amount` along this axis.
  Rigid3d (*move)(const Rigid3d& world_from_cam, double amount);
};

Rigid3d MoveCamX(const Rigid3d& p, double a) {
  Rigid3d out = p;
  out.translation += p.rotation * Eigen::Vector3d(a, 0, 0);
  return out;
}
Rigid3d MoveCamZ(const Rigid3d& p, double a) {
  Rigid3d out = p;
  out.translation += p.rotation * Eigen::Vector3d(0, 0, a);
  return out;
}
Rigid3d Yaw(const Rigid3d& p, double deg) {
  Rigid3d out = p;
  out.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(
                     DegToRadMulDiv(deg), Eigen::Vector3d::UnitZ())) *
                 p.rotation;
  return out;
}

struct ProfileOptions {
  std::string map_dir, dataset_dir;
  int stride = 5;
  int samples = 10;  // per side of zero
  double step_m = 0.02;
  double step_deg = 0.5;
  MeasurementOptions measurement;
};

int Run(const ProfileOptions& o) {
  const Map map = ReadMap(o.map_dir);
  const Dataset dataset = LoadDataset(o.dataset_dir);
  const Renderer renderer(map);
  const MeasurementModel model(&renderer, dataset.camera, o.measurement);
  const std::vector<Axis> axes = {
      {"camera x", "m", o.step_m, MoveCamX},
      {"camera z", "m", o.step_m, MoveCamZ},
      {"yaw", "deg", o.step_deg, Yaw},
  };
  const int n = 2 * o.samples + 1;
  for (const Axis& axis : axes) {
    std::vector<double> sum(n, 0.0), peaks;
    int frames = 0;
    for (size_t i = 0; i < dataset.frames.size(); i += o.stride) {
      const auto& gt = dataset.frames[i].groundtruth_world_from_cam;
      if (!gt) continue;
      const cv::Mat live = model.PrepareLive(dataset.LoadImage(i));
      std::vector<Rigid3d> poses;
      for (int k = 0; k < n; ++k) {
        poses.push_back(axis.move(*gt, (k - o.samples) * axis.step));
      }
      const std::vector<MeasurementScore> s = model.ScoreBatch(live, poses);
      int best = 0;
      for (int k = 0; k < n; ++k) {
        sum[k] += s[k].log_likelihood - s[o.samples].log_likelihood;
        if (s[k].log_likelihood > s[best].log_likelihood) best = k;
      }
      peaks.push_back((best - o.samples) * axis.step);
      ++frames;
    }
    if (frames == 0) throw InputError(o.dataset_dir + ": no ground truth");
    std::vector<double> abs_peaks;
    for (double p : peaks) abs_peaks.push_back(std::abs(p));
    std::printf("%s (%d frames): peak median %+.3f %s, median |peak| %.3f %s\n",
                axis.name, frames, UpperMedian(peaks), axis.unit,
                UpperMedian(abs_peaks), axis.unit);
    for (int k = 0; k < n; ++k) {
      std::printf("  %+7.3f %s  mean dlogL %+8.3f\n",
                  (k - o.samples) * axis.step, axis.unit, sum[k] / frames);
    }
  }
  return 0;
}

}  // namespace
}  // namespace monomap

int main(int argc, char** argv) {
  monomap::ProfileOptions o;
  CLI::App app{"Shape of the measurement likelihood around the true pose"};
  app.add_option("--map", o.map_dir, "Map directory")->required();
  app.add_option("--dataset", o.dataset_dir, "Dataset with ground truth")
      ->required();
  app.add_option("--stride", o.stride, "Every n-th frame");
  app.add_option("--samples", o.samples, "Offsets per side of zero");
  app.add_option("--step-m", o.step_m, "Offset step along x and z (m)");
  app.add_option("--step-deg", o.step_deg, "Offset step of yaw (deg)");
  app.add_option("--width", o.measurement.width, "Measurement width");
  app.add_option("--height", o.measurement.height, "Measurement height");
  app.add_option("--sigma", o.measurement.sigma, "Likelihood temperature");
  return monomap::ParseAndRunSweep(app, argc, argv, "likelihood_profile",
                                   [&] { return monomap::Run(o); });
}
