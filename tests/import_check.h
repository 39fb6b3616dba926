// Shared by the importers' end-to-end tests: a short simulated run to log
// into a bag, and the check that an import of that bag gives back the same
// dataset (poses within 1e-6, identical pixels).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "monomap/io/dataset.h"
#include "monomap/sim/simulate.h"

namespace monomap::test {

// A short simulated hallway run (25 frames, 160x120) in `dir`, loaded
// without its ground truth (what a robot would have logged).
inline Dataset SimulateHallway(const std::filesystem::path& dir) {
  SimulationOptions so;
  so.world = "hallway";
  so.num_frames = 25;
  so.width = 160;
  so.height = 120;
  so.write_structure = false;
  Simulate(so, dir);
  DatasetOptions no_gt;
  no_gt.load_groundtruth = false;
  return LoadDataset(dir, no_gt);
}

inline void ExpectSameDataset(const Dataset& sim, const Dataset& imported) {
  ASSERT_EQ(imported.frames.size(), sim.frames.size());
  ASSERT_TRUE(imported.base_from_cam && sim.base_from_cam);
  const auto pose_error = [](const Rigid3d& a, const Rigid3d& b) {
    return (a.translation - b.translation).norm() +
           AngleBetween(a.rotation, b.rotation);
  };
  EXPECT_LT(pose_error(*imported.base_from_cam, *sim.base_from_cam), 1e-9);
  EXPECT_EQ(imported.camera.width, sim.camera.width);
  EXPECT_EQ(imported.camera.model, sim.camera.model);
  EXPECT_NEAR(imported.camera.fx, sim.camera.fx, 1e-9);
  EXPECT_NEAR(imported.camera.distortion[0], sim.camera.distortion[0], 1e-9);
  double max_pose = 0, max_base = 0, max_dt = 0, max_pixel = 0;
  for (size_t i = 0; i < sim.frames.size(); ++i) {
    const DatasetFrame& a = sim.frames[i];
    const DatasetFrame& b = imported.frames[i];
    max_dt = std::max(max_dt, std::abs(a.timestamp - b.timestamp));
    max_pose = std::max(max_pose, pose_error(a.odometry_world_from_cam,
                                             b.odometry_world_from_cam));
    max_base = std::max(
        max_base,
        std::abs(a.odometry_base->x - b.odometry_base->x) +
            std::abs(a.odometry_base->y - b.odometry_base->y) +
            std::abs(std::remainder(a.odometry_base->yaw - b.odometry_base->yaw,
                                    2 * M_PI)));
    cv::Mat diff;
    cv::absdiff(sim.LoadImage(i, true), imported.LoadImage(i, true), diff);
    double worst = 0;
    cv::minMaxLoc(diff.reshape(1), nullptr, &worst);
    max_pixel = std::max(max_pixel, worst);
  }
  EXPECT_LT(max_dt, 1e-6);
  EXPECT_LT(max_pose, 1e-6);
  EXPECT_LT(max_base, 1e-6);
  EXPECT_EQ(max_pixel, 0.0);
}

}  // namespace monomap::test
