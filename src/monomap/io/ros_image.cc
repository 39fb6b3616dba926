#include "monomap/io/ros_image.h"

#include "monomap/io/bag_import.h"

namespace monomap {

cv::Mat PixelsOfImageMsg(const sensor_msgs::Image& msg,
                         const std::string& where) {
  return bag::RawImagePixels(msg.encoding, msg.width, msg.height, msg.step,
                             msg.data.data(), msg.data.size(), where);
}

}  // namespace monomap
