#include "monomap/localization/measurement_model.h"

#include <cmath>

#include <gtest/gtest.h>

#include "monomap/localization/particle_filter.h"
#include "monomap/sim/test_scene.h"
#include "monomap/util/error.h"

namespace monomap {
namespace {

constexpr double kDeg = M_PI / 180.0;

class MeasurementTest : public ::testing::Test {
 protected:
  MeasurementTest()
      : map_(testing::RoomMap()),
        renderer_(map_),
        camera_(testing::LiveCamera()),
        model_(&renderer_, camera_) {}

  Map map_;
  Renderer renderer_;
  Camera camera_;
  MeasurementModel model_;
};

TEST_F(MeasurementTest, TruePoseBeatsDisplacedPoses) {
  const Rigid3d mount = testing::BaseFromCam();
  for (const Pose2d& base : {Pose2d{0.3, 0.2, 0.3}, Pose2d{1.2, -0.5, -0.8},
                             Pose2d{0.5, 0.6, 2.5}}) {
    const Rigid3d truth = WorldFromCamOfBase(base, mount);
    // Gain and offset change plus sensor noise.
    const cv::Mat raw = testing::LiveImage(renderer_, camera_, truth, 0.7,
                                              25, 3.0, 1);
    const cv::Mat live = model_.PrepareLive(raw);
    ASSERT_EQ(live.cols, 80);
    ASSERT_EQ(live.rows, 60);
    const MeasurementScore s_true = model_.Score(live, truth);
    EXPECT_GT(s_true.ncc, 0.9);
    EXPECT_GT(s_true.coverage, 0.9);
    const std::vector<Rigid3d> displaced = {
        WorldFromCamOfBase({base.x + 0.05, base.y, base.yaw}, mount),
        WorldFromCamOfBase({base.x, base.y - 0.05, base.yaw}, mount),
        WorldFromCamOfBase({base.x, base.y, base.yaw + 3 * kDeg}, mount),
        WorldFromCamOfBase({base.x, base.y, base.yaw - 3 * kDeg}, mount),
        truth * Rigid3d(QuaternionFromRotationVector({3 * kDeg, 0, 0}),
                        Eigen::Vector3d::Zero()),
        Rigid3d(truth.rotation,
                truth.translation + Eigen::Vector3d(0, 0, 0.05)),
    };
    const std::vector<MeasurementScore> scores =
        model_.ScoreBatch(live, displaced);
    for (size_t i = 0; i < scores.size(); ++i) {
      EXPECT_LT(scores[i].log_likelihood, s_true.log_likelihood - 1.0)
          << "pose " << i << " ncc " << scores[i].ncc << " vs "
          << s_true.ncc;
    }
  }
}

TEST_F(MeasurementTest, UndistortionMatchesPinholeRender) {
  const Rigid3d truth =
      WorldFromCamOfBase({0.3, 0.1, 0.2}, testing::BaseFromCam());
  const cv::Mat raw =
      testing::LiveImage(renderer_, camera_, truth, 1.0, 0, 0.0, 1);
  const cv::Mat undist = model_.preparer().Undistort(raw);
  cv::Mat pinhole, depth;
  renderer_.Render(camera_.Pinhole(), truth, &pinhole, &depth);
  double ncc = 0, cov = 0;
  MeasurementModel::Ncc(pinhole, depth, undist, 20, &ncc, &cov);
  EXPECT_GT(ncc, 0.97);
  // Without undistortion the image matches worse.
  double ncc_raw = 0;
  MeasurementModel::Ncc(pinhole, depth, raw, 20, &ncc_raw, &cov);
  EXPECT_LT(ncc_raw, ncc - 0.02);
}

TEST_F(MeasurementTest, LittleMapIsPenalized) {
  EXPECT_LT(model_.LogLikelihood(0.95, 0.05), model_.LogLikelihood(0.8, 0.9));
  EXPECT_DOUBLE_EQ(model_.LogLikelihood(1.0, 1.0), 0.0);
  // A pose looking at the sky (camera up through the ceiling) sees nothing.
  const Rigid3d up(QuaternionFromRotationVector({M_PI / 2, 0, 0}),
                   Eigen::Vector3d(0, 0, 2.0));
  const cv::Mat live(60, 80, CV_8UC1, cv::Scalar(100));
  const MeasurementScore s = model_.Score(live, up);
  EXPECT_EQ(s.ncc, 0.0);
  EXPECT_NEAR(s.log_likelihood, -1.0 / model_.options().sigma, 1e-9);
}

TEST(MeasurementOptions, CheckRejectsBadValues) {
  MeasurementOptions o;
  o.sigma = 0;
  EXPECT_THROW(o.Check(), OptionsError);
  o = {};
  o.width = 2;
  EXPECT_THROW(o.Check(), OptionsError);
}

}  // namespace
}  // namespace monomap
