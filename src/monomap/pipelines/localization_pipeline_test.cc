#include "monomap/pipelines/localization_pipeline.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "monomap/io/map_format.h"
#include "monomap/sim/test_scene.h"
#include "monomap/util/angles.h"
#include "monomap/util/error.h"

namespace monomap {
namespace {

// Composes a planar motion (forward, turn) given in the base frame.
Pose2d Forward(const Pose2d& a, double fwd, double turn) {
  return {a.x + fwd * std::cos(a.yaw), a.y + fwd * std::sin(a.yaw),
          a.yaw + turn};
}

// A dataset of a short drive through the test room: images rendered at
// the true poses, odometry with its own origin (0.36 m and 11 degrees from
// the true start) and 5 % scale error, ground truth.
class LocalizationPipelineTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("monomap_localization_pipeline_test_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
    testing::TestSceneOptions o;
    o.layout = testing::TestLayout::kRoom;
    o.seed = 0;  // image noise seeded by the frame index
    o.room.render_images = true;
    o.room.gain = 0.9;
    o.room.offset = 5;
    o.room.noise_sigma = 2.0;
    Pose2d truth{0.0, 0.3, -0.2};
    for (int i = 0; i < 10; ++i) {
      o.room.base_poses.push_back(truth);
      truth = Forward(truth, 0.03, DegToRad(1.0));
    }
    const testing::TestScene scene = testing::MakeTestScene(o);
    map_ = scene.map;
    truth_ = scene.world_from_cam;
    ds_.root = dir_;
    ds_.camera = scene.camera;
    ds_.base_from_cam = scene.base_from_cam;
    ds_.has_groundtruth = true;
    Pose2d odometry{0, 0, 0};
    for (int i = 0; i < 10; ++i) {
      DatasetFrame f;
      f.timestamp = 0.1 * i;
      f.image_path = dir_ / ("f" + std::to_string(i) + ".png");
      cv::imwrite(f.image_path.string(), scene.images[i]);
      f.odometry_base = odometry;
      f.odometry_world_from_cam =
          WorldFromCamOfBase(odometry, scene.base_from_cam);
      f.groundtruth_world_from_cam = truth_[i];
      ds_.frames.push_back(f);
      odometry = Forward(odometry, 0.03 * 1.05, DegToRad(1.1));
    }
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::filesystem::path dir_;
  Map map_;
  Dataset ds_;
  std::vector<Rigid3d> truth_;
};

LocalizationPipelineOptions Mcc200() {
  LocalizationPipelineOptions o;
  o.show_progress = false;
  o.localizer.method = LocalizationMethod::kMcc;
  o.localizer.mcl.num_particles = 200;
  o.localizer.mcl.kld.max_particles = 200;
  return o;
}

TEST_F(LocalizationPipelineTest, StartsAtTheFirstOdometryPoseNotTheTruth) {
  // MCL without injection: nothing but the odometry moves the particles,
  // so after one update none of them is near the truth.
  LocalizationPipelineOptions o = Mcc200();
  o.localizer.method = LocalizationMethod::kMcl;
  o.localizer.recovery.injection_fraction = 0.0;
  o.localizer.recovery.relocalize_ncc_drop = 0.0;
  Dataset first = ds_;
  first.frames.resize(1);
  std::vector<TimedPose> trajectory;
  std::vector<std::vector<Particle>> sets;
  LocalizeSequence(map_, first, o, &trajectory, &sets);
  ASSERT_EQ(sets.size(), 1u);
  const Eigen::Vector3d odometry_start =
      first.frames[0].odometry_world_from_cam.translation;
  double nearest_to_truth = 1e9, farthest_from_odometry = 0.0;
  for (const Particle& p : sets[0]) {
    const Eigen::Vector3d& t = p.world_from_cam.translation;
    nearest_to_truth =
        std::min(nearest_to_truth, (t - truth_[0].translation).norm());
    farthest_from_odometry =
        std::max(farthest_from_odometry, (t - odometry_start).norm());
  }
  EXPECT_LT(farthest_from_odometry, 0.3);
  EXPECT_GT(nearest_to_truth, 0.1);
}

TEST_F(LocalizationPipelineTest, TracksFromAGivenPoseAndReportsErrors) {
  LocalizationPipelineOptions o = Mcc200();
  o.localizer.init.pose = truth_[0];
  std::vector<TimedPose> trajectory;
  std::vector<std::vector<Particle>> sets;
  const LocalizationReport r =
      LocalizeSequence(map_, ds_, o, &trajectory, &sets);
  EXPECT_EQ(r.frames, 10);
  ASSERT_EQ(trajectory.size(), 10u);
  EXPECT_EQ(sets.size(), 10u);
  EXPECT_NEAR(trajectory[3].timestamp, 0.3, 1e-12);
  ASSERT_TRUE(r.has_errors);
  EXPECT_LT(r.rmse_translation_m, 0.01);
  EXPECT_LT(r.mean_rotation_error_deg, 0.5);
  EXPECT_DOUBLE_EQ(r.fraction_within_10cm, 1.0);
  // Removing one rigid offset leaves no more than the absolute error.
  ASSERT_TRUE(std::isfinite(r.mean_rotation_error_rigid_deg));
  EXPECT_LE(r.mean_rotation_error_rigid_deg, r.mean_rotation_error_deg);
  EXPECT_LT(r.mean_translation_error_rigid_m, r.rmse_translation_m);
  // The final error is the last estimate's distance to the truth.
  EXPECT_DOUBLE_EQ(
      r.final_translation_error_m,
      (trajectory.back().world_from_cam.translation - truth_.back().translation)
          .norm());

  const nlohmann::json j = r.ToJson();
  EXPECT_EQ(j["frames"].get<int>(), 10);
  EXPECT_DOUBLE_EQ(j["rmse_translation_m"].get<double>(), r.rmse_translation_m);
  EXPECT_DOUBLE_EQ(j["mean_rotation_error_rigid_deg"].get<double>(),
                   r.mean_rotation_error_rigid_deg);
  ASSERT_EQ(j["steps"].size(), 10u);
  EXPECT_EQ(j["steps"][9]["particles"].get<int>(), r.steps[9].particles);
  EXPECT_EQ(j["steps"][9].size(), 14u);
  // Without ground truth there are no error fields.
  Dataset no_truth = ds_;
  for (DatasetFrame& f : no_truth.frames) f.groundtruth_world_from_cam.reset();
  o.localizer.method = LocalizationMethod::kMcl;
  const LocalizationReport r2 = LocalizeSequence(map_, no_truth, o, nullptr);
  EXPECT_FALSE(r2.has_errors);
  EXPECT_FALSE(r2.ToJson().contains("rmse_translation_m"));
  EXPECT_FALSE(r2.ToJson().contains("mean_rotation_error_rigid_deg"));
}

TEST_F(LocalizationPipelineTest, PlanarStateNeedsTheMountAnd2dOdometry) {
  const LocalizationPipelineOptions o = Mcc200();
  std::vector<TimedPose> trajectory;
  Dataset no_mount = ds_;
  no_mount.base_from_cam.reset();
  EXPECT_THROW(LocalizeSequence(map_, no_mount, o, &trajectory), InputError);
  Dataset no_2d = ds_;
  no_2d.frames[4].odometry_base.reset();
  try {
    LocalizeSequence(map_, no_2d, o, &trajectory);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("odometry2d.txt"), std::string::npos);
  }
}

TEST_F(LocalizationPipelineTest, SessionFromAMapDirectoryReplaysLikeLocalize) {
  // What a robot does: open the written map, feed the frames one by one.
  // It must give what `monomap localize` (LocalizeSequence) gives.
  const std::filesystem::path map_dir = dir_ / "map";
  std::filesystem::create_directories(map_dir);
  map_.camera = ds_.camera.Pinhole();
  WriteMap(map_dir, map_);
  LocalizationPipelineOptions o = Mcc200();
  std::vector<TimedPose> expected;
  LocalizeSequence(ReadMap(map_dir), ds_, o, &expected);
  SessionOptions so;
  so.localizer = o.localizer;
  const std::unique_ptr<LocalizationSession> session =
      OpenLocalizationSession(map_dir, so, ds_.camera, ds_.base_from_cam);
  for (size_t i = 0; i < ds_.frames.size(); ++i) {
    SessionFrame f;
    f.stamp = ds_.frames[i].timestamp;
    f.image = ds_.LoadImage(i);
    f.odom_from_cam = ds_.frames[i].odometry_world_from_cam;
    f.odom_base = ds_.frames[i].odometry_base;
    const SessionResult r = session->Process(f);
    EXPECT_EQ(r.world_from_cam.translation,
              expected[i].world_from_cam.translation)
        << "frame " << i;
  }
  EXPECT_THROW(OpenLocalizationSession(dir_ / "no_map", so), InputError);
}

}  // namespace
}  // namespace monomap
