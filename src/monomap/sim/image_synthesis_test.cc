#include "monomap/sim/image_synthesis.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "monomap/sim/world.h"
#include "monomap/util/error.h"

namespace monomap {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

Camera SmallCamera() {
  Camera c;
  c.width = 160;
  c.height = 120;
  c.fx = c.fy = 125.0;
  c.cx = 79.5;
  c.cy = 59.5;
  c.distortion = {-0.25, 0.07, 0, 0, 0};
  return c;
}

// A dark plane z = depth (in world) with a Gaussian blob of sigma
// `sigma_m` centred exactly at `x`.
TexturedPlane BlobPlane(double depth, const std::vector<Vector3d>& blobs,
                        double sigma_m) {
  const double ppm = 200.0;
  TexturedPlane p = MakeRectanglePlane(0, Vector3d(-4, -3, depth),
                                       Vector3d::UnitX(), Vector3d::UnitY(),
                                       8.0, 6.0, ppm);
  cv::Mat grey(p.texture.size(), CV_8U, cv::Scalar(20));
  for (const Vector3d& x : blobs) {
    const Vector2d c = p.TextureFromWorld(x);
    const double s = sigma_m * ppm;
    for (int r = std::max(0, int(c.y() - 5 * s)); r < std::min(grey.rows, int(c.y() + 5 * s)); ++r) {
      for (int col = std::max(0, int(c.x() - 5 * s)); col < std::min(grey.cols, int(c.x() + 5 * s)); ++col) {
        const double d2 = (Vector2d(col, r) - c).squaredNorm();
        grey.at<uchar>(r, col) = cv::saturate_cast<uchar>(
            20 + 220 * std::exp(-d2 / (2 * s * s)));
      }
    }
  }
  cv::cvtColor(grey, p.texture, cv::COLOR_GRAY2BGRA);
  return p;
}

// Centroid of (image - background) in a window around `guess`.
Vector2d Centroid(const cv::Mat& grey, const Vector2d& guess, int half) {
  double sw = 0, sx = 0, sy = 0;
  for (int y = int(std::round(guess.y())) - half; y <= int(std::round(guess.y())) + half; ++y) {
    for (int x = int(std::round(guess.x())) - half; x <= int(std::round(guess.x())) + half; ++x) {
      if (x < 0 || y < 0 || x >= grey.cols || y >= grey.rows) continue;
      const double w = std::max(0.0, grey.at<float>(y, x) - 20.0);
      sw += w;
      sx += w * x;
      sy += w * y;
    }
  }
  return {sx / sw, sy / sw};
}

TEST(ImageSynthesisTest, WorldPointsProjectWhereTheyAreRendered) {
  const Camera cam = SmallCamera();
  // A camera pose away from identity so the pose convention is exercised.
  const Rigid3d world_from_cam(
      QuaternionFromRotationVector(Vector3d(0.05, -0.1, 0.08)),
      Vector3d(0.3, -0.2, 0.1));
  const double depth = 3.0;
  // Blob centres where the rays of chosen pixels (centre and far corners,
  // where the distortion is strongest) meet the plane.
  const std::vector<Vector2d> targets = {
      {80, 60}, {145, 108}, {14, 12}, {150, 20}, {30, 100}};
  std::vector<Vector3d> blobs;
  for (const Vector2d& px : targets) {
    const Vector3d ray = world_from_cam.rotation *
                         cam.NormalizedFromImage(px).homogeneous();
    const Vector3d c = world_from_cam.translation;
    blobs.push_back(c + ray * ((depth - c.z()) / ray.z()));
  }
  SceneRenderer renderer(cam, {});
  renderer.AddPlane(BlobPlane(depth, blobs, 0.03));
  cv::Mat radiance = renderer.Render(world_from_cam);
  cv::Mat grey;
  cv::cvtColor(radiance, grey, cv::COLOR_BGR2GRAY);
  double max_err = 0;
  for (const Vector3d& x : blobs) {
    const Vector2d expected =
        cam.ImageFromCam(world_from_cam.Inverse() * x);
    const Vector2d found = Centroid(grey, expected, 5);
    max_err = std::max(max_err, (found - expected).norm());
  }
  EXPECT_LT(max_err, 0.25);
}

TEST(ImageSynthesisTest, NearestPlaneOccludesAndPolygonBounds) {
  const Camera cam = SmallCamera();
  SceneRenderer renderer(cam, {});
  TexturedPlane far = MakeRectanglePlane(0, Vector3d(-5, -5, 4),
                                         Vector3d::UnitX(), Vector3d::UnitY(),
                                         10, 10, 20);
  far.texture.setTo(cv::Scalar(200, 200, 200, 255));
  // A small square nearer the camera, in front of the image centre.
  TexturedPlane near = MakeRectanglePlane(1, Vector3d(-0.25, -0.25, 2),
                                          Vector3d::UnitX(),
                                          Vector3d::UnitY(), 0.5, 0.5, 20);
  near.texture.setTo(cv::Scalar(50, 50, 50, 255));
  renderer.AddPlane(far);
  renderer.AddPlane(near);
  const cv::Mat index = renderer.RenderPlaneIndex(Rigid3d::Identity());
  const cv::Mat rad = renderer.Render(Rigid3d::Identity());
  // The square spans +-0.25 m at 2 m: +-15.6 px around the centre (the
  // distortion is negligible there).
  EXPECT_EQ(index.at<int>(60, 80), 1);
  EXPECT_EQ(index.at<int>(60, 80 + 13), 1);
  EXPECT_EQ(index.at<int>(60, 80 + 18), 0);
  EXPECT_EQ(index.at<int>(5, 5), 0);
  EXPECT_NEAR(rad.at<cv::Vec3f>(60, 80)[0], 50.0, 0.5);
  EXPECT_NEAR(rad.at<cv::Vec3f>(5, 5)[0], 200.0, 0.5);
  // Behind the camera nothing is drawn: the background shows.
  const Rigid3d turned(QuaternionFromRotationVector(Vector3d(0, M_PI, 0)),
                       Vector3d::Zero());
  const cv::Mat back = renderer.Render(turned);
  EXPECT_NEAR(back.at<cv::Vec3f>(60, 80)[0], RenderOptions().background,
              1e-3);
  renderer.SetPlaneVisible(1, false);
  EXPECT_EQ(renderer.RenderPlaneIndex(Rigid3d::Identity()).at<int>(60, 80),
            0);
}

TEST(ImageSynthesisTest, MipMappingAvoidsAliasing) {
  // A fine 1-texel checkerboard far away must render as its mean grey, not
  // as moire.
  const Camera cam = SmallCamera();
  TexturedPlane p = MakeRectanglePlane(0, Vector3d(-20, -15, 10),
                                       Vector3d::UnitX(), Vector3d::UnitY(),
                                       40, 30, 50);
  cv::Mat grey(p.texture.size(), CV_8U);
  for (int r = 0; r < grey.rows; ++r)
    for (int c = 0; c < grey.cols; ++c)
      grey.at<uchar>(r, c) = ((r + c) % 2) ? 220 : 20;
  cv::cvtColor(grey, p.texture, cv::COLOR_GRAY2BGRA);
  SceneRenderer renderer(cam, {});
  renderer.AddPlane(p);
  cv::Mat rad = renderer.Render(Rigid3d::Identity());
  cv::Scalar mean, stddev;
  cv::meanStdDev(rad, mean, stddev);
  EXPECT_NEAR(mean[0], 120.0, 5.0);
  EXPECT_LT(stddev[0], 5.0);
}

TEST(ImageSynthesisTest, CameraEffects) {
  cv::Mat flat(120, 160, CV_32FC3, cv::Scalar(100, 100, 100));
  const cv::Mat exact = ApplyCameraEffects(flat, 0.0,
                                           CameraEffectsOptions::None(), 1, 1);
  ASSERT_EQ(exact.type(), CV_8UC1);
  EXPECT_EQ(cv::norm(exact, cv::Mat(120, 160, CV_8U, cv::Scalar(100)),
                     cv::NORM_INF), 0.0);
  CameraEffectsOptions noisy = CameraEffectsOptions::None();
  noisy.noise_sigma = 2.0;
  const cv::Mat a = ApplyCameraEffects(flat, 0.0, noisy, 1, 7);
  const cv::Mat b = ApplyCameraEffects(flat, 0.0, noisy, 1, 7);
  const cv::Mat c = ApplyCameraEffects(flat, 0.0, noisy, 1, 8);
  cv::Scalar mean, stddev;
  cv::meanStdDev(a, mean, stddev);
  EXPECT_NEAR(stddev[0], 2.0, 0.25);
  EXPECT_NEAR(mean[0], 100.0, 0.2);
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(a, c, cv::NORM_INF), 0.0);
  // Exposure: smooth and bounded.
  CameraEffectsOptions exp;
  double gmin = 10, gmax = 0, max_step = 0;
  for (int i = 0; i < 900; ++i) {
    const double g = ExposureGain(i / 30.0, exp, 3);
    gmin = std::min(gmin, g);
    gmax = std::max(gmax, g);
    max_step = std::max(max_step,
                        std::abs(g - ExposureGain((i + 1) / 30.0, exp, 3)));
  }
  EXPECT_GT(gmax - gmin, exp.exposure_variation);
  EXPECT_LE(gmax, 1 + exp.exposure_variation + 1e-9);
  EXPECT_GE(gmin, 1 - exp.exposure_variation - 1e-9);
  EXPECT_LT(max_step, 0.01);
  exp.color = true;
  EXPECT_EQ(ApplyCameraEffects(flat, 0.0, exp, 1, 1).type(), CV_8UC3);
  exp.noise_sigma = -1;
  EXPECT_THROW(exp.Check(), OptionsError);
}

TEST(ImageSynthesisTest, SpecularPointObeysReflectionLaw) {
  const Vector3d light(2.0, 1.0, 2.5), cam(0.5, -0.3, 0.6);
  Vector3d p;
  ASSERT_TRUE(SpecularPoint(light, cam, 0.0, &p));
  EXPECT_NEAR(p.z(), 0.0, 1e-12);
  const Vector3d to_light = (light - p).normalized();
  const Vector3d to_cam = (cam - p).normalized();
  // Equal elevation angles and coplanar with the normal.
  EXPECT_NEAR(to_light.z(), to_cam.z(), 1e-12);
  EXPECT_NEAR((to_light + to_cam).head<2>().norm(), 0.0, 1e-12);
}

TEST(ImageSynthesisTest, DiscObjectFacesCamera) {
  const TexturedPlane disc = MakeDiscObject(0.3, 100, 1);
  EXPECT_EQ(disc.polygon.size(), 32u);
  Plane plane;
  PlaneFrame frame;
  const Vector3d centre(1, 2, 0.5);
  PlaceDisc(0.3, centre, Vector3d(-1, 0, 0), &plane, &frame);
  EXPECT_LT((frame.Normal() - plane.normal).norm(), 1e-12);
  EXPECT_NEAR(plane.SignedDistance(centre), 0.0, 1e-12);
  EXPECT_LT((frame.ToWorld(Vector2d(0.3, 0.3)) - centre).norm(), 1e-12);
  EXPECT_NEAR(frame.v_axis.z(), -1.0, 1e-12);
}

}  // namespace
}  // namespace monomap
