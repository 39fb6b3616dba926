// The pixels of a ROS 1 sensor_msgs/Image, shared by the bag importer and
// the ROS node (ros/). Needs the ROS 1 message headers (C++17).
#pragma once

#include <sensor_msgs/Image.h>

#include <opencv2/core.hpp>
#include <string>

namespace monomap {

// mono8 -> 8-bit gray, bgr8 and rgb8 -> BGR; a copy (rows may be padded).
// Throws InputError naming `where` and the encoding or the size that does
// not fit.
cv::Mat PixelsOfImageMsg(const sensor_msgs::Image& msg,
                         const std::string& where);

}  // namespace monomap
