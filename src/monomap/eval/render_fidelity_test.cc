#include "monomap/eval/render_fidelity.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "monomap/rendering/renderer.h"
#include "monomap/util/error.h"

namespace monomap {
namespace {

// A 1 m x 1 m textured plane at z = 1 facing a pinhole camera at the
// origin (the texture: smoothed noise, rich at every scale).
Map PlaneMap(Camera* camera) {
  camera->width = 320;
  camera->height = 240;
  camera->fx = camera->fy = 200;
  camera->cx = 159.5;
  camera->cy = 119.5;
  Map map;
  map.camera = *camera;
  TexturedPlane p;
  p.id = 0;
  p.frame.origin = {-0.5, 0.5, 1.0};
  p.frame.u_axis = {1, 0, 0};
  p.frame.v_axis = {0, -1, 0};  // normal u x v = -z: towards the camera
  p.plane.normal = {0, 0, -1};
  p.plane.offset = 1.0;
  p.pixels_per_meter = 400;
  cv::Mat noise(400, 400, CV_8UC1);
  cv::randu(noise, 0, 255);
  cv::GaussianBlur(noise, noise, {0, 0}, 2.0);
  cv::normalize(noise, noise, 0, 255, cv::NORM_MINMAX);
  cv::cvtColor(noise, p.texture, cv::COLOR_GRAY2BGRA);
  p.polygon = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  map.planes.push_back(p);
  return map;
}

TEST(RenderFidelity, ExactImageUpToGainOffsetAndNoise) {
  Camera camera;
  const Map map = PlaneMap(&camera);
  const Renderer renderer(map);
  const Rigid3d pose;  // identity: at the origin looking along +z
  cv::Mat render;
  renderer.Render(camera, pose, &render);
  // The "real" image: other exposure (gain 0.8, offset 20) and noise 2.
  cv::Mat noise(render.size(), CV_32F);
  cv::randn(noise, 0.0, 2.0);
  cv::Mat real_f;
  render.convertTo(real_f, CV_32F, 0.8, 20.0);
  cv::Mat real;
  cv::Mat(real_f + noise).convertTo(real, CV_8U);

  RenderFidelityOptions options;
  options.width = 0;  // compare at full size
  const Rigid3d wrong(Eigen::Quaterniond::Identity(),
                      Eigen::Vector3d(0.03, 0.0, 0.0));
  const RenderFidelity r = EvaluateRenderFidelity(
      map, camera, {pose, wrong}, {real, real}, {7, 8}, options);
  ASSERT_EQ(r.frames.size(), 2u);
  EXPECT_EQ(r.frames[0].frame, 7);
  // 1 m at 1 m with f = 200: a 200 x 200 px square of the 320 x 240 view.
  EXPECT_NEAR(r.frames[0].coverage, 200.0 * 200.0 / (320 * 240), 0.01);
  EXPECT_GT(r.frames[0].ncc, 0.98);
  // Residual = the noise (sigma 2, quantised): PSNR ~ 20 log10(255 / 2).
  EXPECT_NEAR(r.frames[0].psnr_db, 20 * std::log10(255.0 / 2.0), 1.5);
  // 3 cm off at 1 m = 6 px: the texture no longer lines up.
  EXPECT_LT(r.frames[1].ncc, 0.5);
  EXPECT_LT(r.frames[1].psnr_db, r.frames[0].psnr_db - 10.0);
  EXPECT_EQ(r.ncc.count, 2u);
}

TEST(RenderFidelity, SkipsFramesThatSeeTooLittleMapAndChecksInput) {
  Camera camera;
  const Map map = PlaneMap(&camera);
  // Looking away (rotated 180 degrees about y): nothing of the map.
  const Rigid3d away(
      Eigen::Quaterniond(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY())),
      Eigen::Vector3d::Zero());
  const cv::Mat image(camera.height, camera.width, CV_8UC1, cv::Scalar(100));
  const RenderFidelity r = EvaluateRenderFidelity(
      map, camera, {away}, {image}, {0}, RenderFidelityOptions());
  EXPECT_TRUE(r.frames.empty());
  EXPECT_EQ(r.skipped, 1);
  const cv::Mat small(10, 10, CV_8UC1, cv::Scalar(0));
  EXPECT_THROW(EvaluateRenderFidelity(map, camera, {Rigid3d()}, {small}, {0},
                                      RenderFidelityOptions()),
               InputError);
  EXPECT_THROW(EvaluateRenderFidelity(map, camera, {Rigid3d()}, {}, {0},
                                      RenderFidelityOptions()),
               InputError);
  RenderFidelityOptions bad;
  bad.min_coverage = 2.0;
  EXPECT_THROW(bad.Check(), OptionsError);
}

TEST(RenderFidelity, CompareMaskedNeedsTexture) {
  const cv::Mat flat(8, 8, CV_8UC1, cv::Scalar(50));
  const cv::Mat mask(8, 8, CV_8UC1, cv::Scalar(255));
  double ncc = 0, psnr = 0;
  EXPECT_FALSE(CompareMasked(flat, flat, mask, &ncc, &psnr));
}

TEST(PoseDiscriminationTest, CountsFramesWhereTheTruePoseMatchesBetter) {
  RenderFidelity truth, wrong;
  truth.frames = {{0, 0.5, 0.9, 30}, {5, 0.5, 0.4, 20}, {10, 0.5, 0.8, 25}};
  // Frame 10 was skipped from the wrong pose; frame 15 has no true render.
  wrong.frames = {{0, 0.5, 0.7, 28}, {5, 0.5, 0.6, 22}, {15, 0.5, 0.1, 10}};
  const PoseDiscrimination d = ComparePoses(truth, wrong);
  EXPECT_EQ(d.compared, 2);
  EXPECT_EQ(d.true_better, 1);
  EXPECT_DOUBLE_EQ(d.TrueBetterShare(), 0.5);
  EXPECT_DOUBLE_EQ(PoseDiscrimination().TrueBetterShare(), 0.0);
}

TEST(PoseDiscriminationTest, MovesAlongEachCamerasOwnXAxis) {
  const Rigid3d turned(
      Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ())),
      {1.0, 0.0, 0.0});
  const std::vector<Rigid3d> moved = MovedAlongCameraX({turned}, 0.25);
  ASSERT_EQ(moved.size(), 1u);
  // The camera's x axis points along world +y.
  EXPECT_LT((moved[0].translation - Eigen::Vector3d(1.0, 0.25, 0.0)).norm(),
            1e-12);
  EXPECT_LT(AngleBetween(moved[0].rotation, turned.rotation), 1e-12);
}

}  // namespace
}  // namespace monomap
