#include "monomap/io/ros2_messages.h"

#include <gtest/gtest.h>

#include "monomap/io/rosbag2_test_bag.h"
#include "monomap/util/error.h"

namespace monomap::ros2 {
namespace {
using rosbag2_test::CdrWriter;

const uint8_t* Bytes(const std::string& s) {
  return reinterpret_cast<const uint8_t*>(s.data());
}

// An Odometry message in either byte order decodes to the same pose; the
// header's odd-length strings exercise the 8-byte alignment of the doubles
// that follow (counted from after the 4-byte encapsulation header).
TEST(Ros2Messages, OdometryInBothByteOrders) {
  const Rigid3d pose(Eigen::Quaterniond(0.9, 0.1, -0.2, 0.3),
                     Eigen::Vector3d(1.5, -2.25, 0.125));
  for (const bool big : {false, true}) {
    CdrWriter w(big);
    w.Header(12.75, "odm");
    w << std::string("b");
    w.Pose(pose);
    const std::string data = w.Data();
    EXPECT_EQ(uint8_t(data[1]), big ? 0 : 1);
    const bag::Transform t = DecodeOdometry(Bytes(data), data.size(), 0, "x");
    EXPECT_EQ(t.parent, "odm");
    EXPECT_EQ(t.child, "b");
    EXPECT_NEAR(t.stamp, 12.75, 1e-9);
    EXPECT_LT((t.parent_from_child.translation - pose.translation).norm(),
              1e-12);
    EXPECT_LT(AngleBetween(t.parent_from_child.rotation, pose.rotation), 1e-9);
  }
}

// The same, laid out by hand byte by byte as the CDR rules say (not by
// fastcdr): little-endian, strings as uint32 length with the terminating
// 0, doubles aligned to 8 bytes counted from after the 4-byte header.
TEST(Ros2Messages, OdometryLaidOutByHand) {
  std::string b("\0\1\0\0", 4);  // encapsulation CDR_LE, options 0
  const auto put = [&b](const void* p, size_t n) {
    b.append(static_cast<const char*>(p), n);
  };
  const int32_t sec = 7;
  const uint32_t nanosec = 500000000, parent_len = 4, child_len = 2;
  put(&sec, 4);          // offset 0 (after the header)
  put(&nanosec, 4);      // 4
  put(&parent_len, 4);   // 8
  put("odm\0", 4);       // 12
  put(&child_len, 4);    // 16
  put("b\0", 2);         // 20
  b.append(2, '\0');     // 22: padding to 24, a multiple of 8
  const double pose[7] = {1.5, -2.25, 0.125, 0.0, 0.0, 0.6, 0.8};
  put(pose, sizeof(pose));  // 24
  const bag::Transform t = DecodeOdometry(Bytes(b), b.size(), 0, "x");
  EXPECT_EQ(t.parent, "odm");
  EXPECT_EQ(t.child, "b");
  EXPECT_DOUBLE_EQ(t.stamp, 7.5);
  EXPECT_EQ(t.parent_from_child.translation, Eigen::Vector3d(1.5, -2.25, 0.125));
  EXPECT_NEAR(t.parent_from_child.rotation.z(), 0.6, 1e-15);
  EXPECT_NEAR(t.parent_from_child.rotation.w(), 0.8, 1e-15);
}

TEST(Ros2Messages, ZeroStampFallsBackToTheRecordingTime) {
  CdrWriter w;
  w.Header(0.0, "cam");
  w << std::string("png");
  w.Bytes({1, 2, 3});
  const std::string data = w.Data();
  const bag::Image m = DecodeImage(Bytes(data), data.size(), true, 42.5, "x");
  EXPECT_EQ(m.stamp, 42.5);
  EXPECT_EQ(m.encoding, "png");
  EXPECT_EQ(m.data.size(), 3u);
}

std::string ErrorOf(const std::string& data) {
  try {
    DecodeTfMessage(Bytes(data), data.size(), 0, "bag.db3: topic '/tf'");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Ros2Messages, CorruptMessagesNameTheField) {
  // Parameter-list encapsulation (kind 3) is not what ROS 2 writes.
  EXPECT_NE(ErrorOf(std::string("\0\3\0\0\0\0\0\0", 8))
                .find("bag.db3: topic '/tf': field 'encapsulation': kind 3 is "
                      "not plain CDR"),
            std::string::npos);
  EXPECT_NE(ErrorOf(std::string("\0\1", 2)).find("truncated"),
            std::string::npos);
  // A transform count no message of this size can hold: refused before
  // any allocation.
  CdrWriter w;
  w << uint32_t(4000000000u);
  EXPECT_NE(ErrorOf(w.Data()).find("field 'transforms': 4000000000 "
                                   "transforms in 8 bytes (corrupt)"),
            std::string::npos)
      << ErrorOf(w.Data());
  // A transform cut in the middle of its frame name.
  CdrWriter cut;
  cut << uint32_t(1);
  cut.Header(1.0, std::string(100, 'f'));
  const std::string data = cut.Data().substr(0, 80);
  EXPECT_NE(ErrorOf(data).find("field 'header.frame_id': truncated or "
                               "corrupt message (80 bytes)"),
            std::string::npos)
      << ErrorOf(data);
}

}  // namespace
}  // namespace monomap::ros2
