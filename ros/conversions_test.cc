// The node's message conversions, without a ROS master.
#include "ros/conversions.h"

#include <gtest/gtest.h>

#include <cstring>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "monomap/util/error.h"

namespace monomap::ros_adapter {
namespace {

sensor_msgs::Image Msg(const cv::Mat& pixels, const std::string& encoding,
                       int padding = 0) {
  sensor_msgs::Image m;
  m.width = pixels.cols;
  m.height = pixels.rows;
  m.encoding = encoding;
  m.step = pixels.cols * pixels.elemSize() + padding;
  m.data.assign(size_t(m.step) * m.height, 0);
  for (int r = 0; r < pixels.rows; ++r) {
    std::memcpy(&m.data[r * m.step], pixels.ptr(r),
                pixels.cols * pixels.elemSize());
  }
  return m;
}

cv::Mat Bgr() {
  cv::Mat bgr(3, 4, CV_8UC3);
  for (int i = 0; i < 36; ++i) bgr.data[i] = uint8_t(7 * i);
  return bgr;
}

double MaxDiff(const cv::Mat& a, const cv::Mat& b) {
  if (a.size() != b.size() || a.type() != b.type()) return 1e9;
  cv::Mat d;
  cv::absdiff(a, b, d);
  double worst = 0;
  cv::minMaxLoc(d.reshape(1), nullptr, &worst);
  return worst;
}

TEST(ImageFromMsg, DecodesMonoBgrRgbWithRowPadding) {
  const cv::Mat bgr = Bgr();
  EXPECT_EQ(MaxDiff(ImageFromMsg(Msg(bgr, "bgr8", 5)), bgr), 0.0);
  cv::Mat rgb;
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  EXPECT_EQ(MaxDiff(ImageFromMsg(Msg(rgb, "rgb8")), bgr), 0.0);
  cv::Mat gray;
  cv::cvtColor(bgr, gray, cv::COLOR_BGR2GRAY);
  const cv::Mat mono = ImageFromMsg(Msg(gray, "mono8", 3));
  EXPECT_EQ(mono.type(), CV_8UC1);
  EXPECT_EQ(MaxDiff(mono, gray), 0.0);
}

TEST(ImageFromMsg, RefusesUnknownEncodingsAndShortData) {
  sensor_msgs::Image m = Msg(Bgr(), "bgr8");
  m.encoding = "16UC1";
  EXPECT_THROW(ImageFromMsg(m), InputError);
  m = Msg(Bgr(), "bgr8");
  m.data.resize(m.data.size() - 1);
  EXPECT_THROW(ImageFromMsg(m), InputError);
}

TEST(ImageFromMsg, DecodesCompressedPngAndRefusesGarbage) {
  sensor_msgs::CompressedImage m;
  m.format = "png";
  cv::imencode(".png", Bgr(), m.data);
  EXPECT_EQ(MaxDiff(ImageFromMsg(m), Bgr()), 0.0);
  m.data.assign(20, 1);
  EXPECT_THROW(ImageFromMsg(m), InputError);
}

TEST(CameraInfoMismatch, ChecksSizeAndIntrinsics) {
  Camera c;
  c.width = 320;
  c.height = 240;
  c.fx = c.fy = 300;
  c.cx = 160;
  c.cy = 120;
  sensor_msgs::CameraInfo info;
  info.width = 320;
  info.height = 240;
  info.K = {300.5, 0, 160, 0, 300, 120, 0, 0, 1};
  EXPECT_EQ(CameraInfoMismatch(info, c, 1.0), "");
  info.K[2] = 163;
  EXPECT_NE(CameraInfoMismatch(info, c, 1.0).find("cx"), std::string::npos);
  info.width = 640;
  EXPECT_NE(CameraInfoMismatch(info, c, 1.0).find("size 640x240"),
            std::string::npos);
}

Rigid3d SomePose() {
  return Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d(
                                                               1, 2, 3)
                                                               .normalized())),
                 Eigen::Vector3d(1.5, -2, 0.25));
}

double Error(const Rigid3d& a, const Rigid3d& b) {
  return (a.translation - b.translation).norm() +
         AngleBetween(a.rotation, b.rotation);
}

TEST(PoseConversions, RoundTripAndCovarianceIsRowMajor) {
  EXPECT_LT(Error(RigidFromMsg(PoseMsg(SomePose())), SomePose()), 1e-12);
  EXPECT_LT(Error(RigidFromMsg(TransformMsg(SomePose())), SomePose()), 1e-12);
  Eigen::Matrix<double, 6, 6> c = Eigen::Matrix<double, 6, 6>::Zero();
  c(0, 1) = 2.0;
  c(5, 5) = 3.0;
  const auto m = CovarianceMsg(c);
  EXPECT_EQ(m[1], 2.0);
  EXPECT_EQ(m[6], 0.0);
  EXPECT_EQ(m[35], 3.0);
}

// map -> odom composed with odom -> base gives the estimated base pose.
TEST(PoseConversions, WorldFromOdomClosesTheTree) {
  const Rigid3d world_from_base = SomePose();
  const Rigid3d odom_from_base(YawRotation(1.0), Eigen::Vector3d(3, 1, 0));
  EXPECT_LT(Error(WorldFromOdom(world_from_base, odom_from_base) *
                      odom_from_base,
                  world_from_base),
            1e-12);
}

TEST(MakeFrame, CameraOdometryThroughTheMountAndPlanarBase) {
  const Rigid3d odom_from_base(YawRotation(0.7), Eigen::Vector3d(2, -1, 0));
  const Rigid3d base_from_cam = SomePose();
  const SessionFrame f = MakeFrame(4.5, cv::Mat(), odom_from_base,
                                   base_from_cam);
  EXPECT_EQ(f.stamp, 4.5);
  EXPECT_LT(Error(f.odom_from_cam, odom_from_base * base_from_cam), 1e-12);
  ASSERT_TRUE(f.odom_base.has_value());
  EXPECT_NEAR(f.odom_base->x, 2, 1e-12);
  EXPECT_NEAR(f.odom_base->y, -1, 1e-12);
  EXPECT_NEAR(f.odom_base->yaw, 0.7, 1e-12);
}

// rviz's 2D Pose Estimate: covariance 0.25 m^2 in x and y, (pi/12)^2 in
// yaw -> spreads 0.5 m and 15 deg; the camera through the mount.
TEST(InitialPoseRequest, BasePoseThroughTheMountAndSpreads) {
  geometry_msgs::PoseWithCovariance m;
  const Rigid3d world_from_base(YawRotation(-2.0), Eigen::Vector3d(4, 5, 0));
  m.pose = PoseMsg(world_from_base);
  m.covariance[0] = m.covariance[7] = 0.25;
  m.covariance[35] = std::pow(M_PI / 12, 2);
  const PoseRequest r = InitialPoseRequest(m, SomePose());
  EXPECT_LT(Error(r.world_from_cam, world_from_base * SomePose()), 1e-9);
  ASSERT_TRUE(r.spread_m && r.spread_deg);
  EXPECT_NEAR(*r.spread_m, 0.5, 1e-12);
  EXPECT_NEAR(*r.spread_deg, 15.0, 1e-9);
  m.covariance.fill(0.0);
  const PoseRequest d = InitialPoseRequest(m, SomePose());
  EXPECT_FALSE(d.spread_m || d.spread_deg);
}

TEST(OdometryBuffer, InterpolatesInsideAndRefusesOutside) {
  OdometryBuffer b(/*span_s=*/1.0);
  EXPECT_FALSE(b.At(0.0, 1.0));
  EXPECT_TRUE(b.Add(10.0, Rigid3d(YawRotation(0.0), Eigen::Vector3d(0, 0, 0))));
  EXPECT_TRUE(b.Add(10.2, Rigid3d(YawRotation(0.4), Eigen::Vector3d(2, 0, 0))));
  EXPECT_FALSE(b.Add(10.1, Rigid3d()));  // backwards: ignored
  const auto mid = b.At(10.05, 0.5);
  ASSERT_TRUE(mid);
  EXPECT_NEAR(mid->translation.x(), 0.5, 1e-12);
  EXPECT_NEAR(PlanarPose(*mid).yaw, 0.1, 1e-12);
  ASSERT_TRUE(b.At(10.2, 0.5));
  EXPECT_FALSE(b.At(10.25, 0.5));  // after the newest: no extrapolation
  EXPECT_FALSE(b.At(9.9, 0.5));    // before the oldest
  EXPECT_FALSE(b.At(10.05, 0.1));  // across a gap longer than allowed
  // Samples older than the span are forgotten.
  EXPECT_TRUE(b.Add(11.5, Rigid3d()));
  EXPECT_FALSE(b.At(10.2, 5.0));
  EXPECT_EQ(*b.newest_stamp(), 11.5);
}

}  // namespace
}  // namespace monomap::ros_adapter
