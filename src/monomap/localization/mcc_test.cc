#include "monomap/localization/mcc.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "monomap/localization/measurement_model.h"
#include "monomap/localization/particle_filter.h"
#include "monomap/sim/test_scene.h"

namespace monomap {
namespace {

constexpr double kDeg = M_PI / 180.0;
// Pitch that leaves part of the room views above the walls (degrees).
constexpr double kTiltUpDeg = 45.0;

// The synthetic room, a corrector on it and live views of three poses.
class MccTest : public ::testing::Test {
 protected:
  struct View {
    Rigid3d truth;
    cv::Mat live;  // prepared for the corrector
  };
  std::vector<View> Views() const {
    std::vector<View> views;
    int n = 0;
    for (const Pose2d& base : {Pose2d{0.3, 0.2, 0.3}, Pose2d{1.2, -0.5, -0.8},
                               Pose2d{0.5, 0.6, 2.5}}) {
      View v;
      v.truth = WorldFromCamOfBase(base, testing::BaseFromCam());
      const cv::Mat raw =
          testing::LiveImage(renderer_, camera_, v.truth, 0.8, 15, 2.0, ++n);
      v.live = LiveImagePreparer::Downscale(
          prep_.Undistort(raw), mcc_.options().width, mcc_.options().height);
      views.push_back(std::move(v));
    }
    return views;
  }

  const Map map_ = testing::RoomMap();
  const Renderer renderer_{map_};
  const Camera camera_ = testing::LiveCamera();
  const MonteCarloCorrector mcc_{&renderer_, camera_};
  const LiveImagePreparer prep_{camera_};
};

TEST_F(MccTest, CorrectsAnOffsetParticle) {
  int n = 0;
  for (const auto& [truth, live] : Views()) {
    ++n;
    // Offset (2 cm, -1 cm) in the world and 1 degree about the camera's
    // vertical axis.
    const Rigid3d offset(
        QuaternionFromRotationVector({0, 1 * kDeg, 0}) * truth.rotation,
        truth.translation + Eigen::Vector3d(0.02, -0.01, 0));
    const MccResult r = mcc_.Correct(live, offset);
    ASSERT_TRUE(r.accepted) << "inliers " << r.inliers << " tracked "
                            << r.tracked << " corners " << r.corners;
    const double et = (r.world_from_cam.translation - truth.translation).norm();
    const double er =
        AngleBetween(r.world_from_cam.rotation, truth.rotation) / kDeg;
    std::printf("pose %d: error %.2f mm %.3f deg, inliers %d/%d, rms %.2f px\n",
                n, et * 1e3, er, r.inliers, r.tracked, r.rms_reprojection_px);
    EXPECT_LT(et, 0.003) << "pose " << n;
    EXPECT_LT(er, 0.2) << "pose " << n;
    EXPECT_GE(r.inliers, 30);
    EXPECT_LT(r.rms_reprojection_px, 0.2);
    EXPECT_NEAR(r.translation_change_m, std::sqrt(0.0005), 0.005);
  }
}

// The basin reaches well beyond a few centimetres: 20 cm back along the
// optical axis (the view shrinks by ~10 %) and 2 degrees of yaw.
// A correction started at the truth moves the inliers by a fraction of a
// pixel: with converged_px 0.5 it stops after one round, without it runs
// both; started 2 cm and 1 deg off, the first round moves them further
// and the second runs too.
TEST_F(MccTest, StopsIteratingOnceARoundMovesLessThanConvergedPx) {
  MccOptions o;
  o.converged_px = 0.5;
  const MonteCarloCorrector early(&renderer_, camera_, o);
  for (const auto& [truth, live] : Views()) {
    const MccResult at = early.Correct(live, truth);
    ASSERT_TRUE(at.accepted);
    EXPECT_LT(at.shift_px, 0.5);
    EXPECT_EQ(at.rounds, 1);
    EXPECT_EQ(mcc_.Correct(live, truth).rounds, 2);
    const Rigid3d off(
        QuaternionFromRotationVector({0, 1 * kDeg, 0}) * truth.rotation,
        truth.translation + Eigen::Vector3d(0.02, -0.01, 0));
    const MccResult r = early.Correct(live, off);
    ASSERT_TRUE(r.accepted);
    EXPECT_EQ(r.rounds, 2);
    EXPECT_LT((r.world_from_cam.translation - truth.translation).norm(), 0.01);
  }
}

// Corners are searched in the bounding box of the map's silhouette only;
// the result must be that of a search of the whole render. Views tilted
// up show the map over part of the image only.
TEST_F(MccTest, FindsTheCornersOfTheWholeRenderWhenTheMapCoversPartOfIt) {
  MccOptions o;
  o.iterations = 1;
  const MonteCarloCorrector one(&renderer_, camera_, o);
  const Renderer biased =
      renderer_.WithMipBias(renderer_.options().mip_bias + o.extra_mip_bias);
  for (const auto& [truth, live] : Views()) {
    const Rigid3d up(truth.rotation * QuaternionFromRotationVector(
                                          {kTiltUpDeg * kDeg, 0, 0}),
                     truth.translation);
    cv::Mat render, depth, mask;
    biased.Render(one.render_camera(), up, &render, &depth);
    const double coverage =
        cv::countNonZero(depth > 0.0f) / static_cast<double>(depth.total());
    ASSERT_GT(coverage, 0.2);
    ASSERT_LT(coverage, 0.8);
    const int side = 2 * o.border_px + 1;
    cv::erode(depth > 0.0f, mask,
              cv::getStructuringElement(cv::MORPH_RECT, cv::Size(side, side)));
    std::vector<cv::Point2f> whole;
    cv::goodFeaturesToTrack(render, whole, o.max_corners, o.corner_quality,
                            o.min_corner_distance_px, mask);
    const MccResult r = one.Correct(live, up);
    EXPECT_GT(r.corners, 20);
    EXPECT_EQ(r.corners, static_cast<int>(whole.size()))
        << "coverage " << coverage;
  }
}

TEST_F(MccTest, CorrectsTwentyCentimetresAlongTheViewAxis) {
  int n = 0;
  for (const auto& [truth, live] : Views()) {
    ++n;
    const Rigid3d offset(
        QuaternionFromRotationVector({0, 0, 2 * kDeg}) * truth.rotation,
        truth.translation + truth.rotation * Eigen::Vector3d(0, 0, -0.2));
    const MccResult r = mcc_.Correct(live, offset);
    ASSERT_TRUE(r.accepted)
        << "pose " << n << ": inliers " << r.inliers << " tracked " << r.tracked
        << " corners " << r.corners;
    const double et = (r.world_from_cam.translation - truth.translation).norm();
    const double er =
        AngleBetween(r.world_from_cam.rotation, truth.rotation) / kDeg;
    std::printf("pose %d from 20 cm: error %.2f mm %.3f deg, inliers %d/%d\n",
                n, et * 1e3, er, r.inliers, r.tracked);
    EXPECT_LT(et, 0.01) << "pose " << n;
    EXPECT_LT(er, 0.3) << "pose " << n;
  }
}

TEST(Mcc, RefusesWithoutMap) {
  const Map map = testing::RoomMap();
  const Renderer renderer(map);
  const MonteCarloCorrector mcc(&renderer, testing::LiveCamera());
  const cv::Mat live(120, 160, CV_8UC1, cv::Scalar(90));
  // Looking up from above the walls: nothing rendered, nothing corrected.
  const Rigid3d up(QuaternionFromRotationVector({M_PI / 2, 0, 0}),
                   Eigen::Vector3d(0, 0, 2.0));
  const MccResult r = mcc.Correct(live, up);
  EXPECT_FALSE(r.accepted);
  EXPECT_EQ(r.corners, 0);
}

}  // namespace
}  // namespace monomap
