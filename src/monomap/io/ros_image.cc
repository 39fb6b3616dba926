#include "monomap/io/ros_image.h"

#include <opencv2/imgproc.hpp>

#include "monomap/util/error.h"

namespace monomap {

cv::Mat PixelsOfImageMsg(const sensor_msgs::Image& msg,
                         const std::string& where) {
  int type = 0;
  if (msg.encoding == "mono8") {
    type = CV_8UC1;
  } else if (msg.encoding == "bgr8" || msg.encoding == "rgb8") {
    type = CV_8UC3;
  } else {
    throw InputError(where, "encoding",
                     "'" + msg.encoding +
                         "' is not supported (mono8, bgr8, rgb8 or "
                         "sensor_msgs/CompressedImage)");
  }
  const size_t row_bytes = size_t(msg.width) * CV_ELEM_SIZE(type);
  if (msg.width == 0 || msg.height == 0 || msg.step < row_bytes ||
      msg.data.size() < size_t(msg.step) * msg.height) {
    throw InputError(where, "data",
                     "holds " + std::to_string(msg.data.size()) +
                         " bytes, too few for " + std::to_string(msg.width) +
                         "x" + std::to_string(msg.height) + " " + msg.encoding);
  }
  // The message's buffer viewed in place, then copied.
  const cv::Mat view(int(msg.height), int(msg.width), type,
                     const_cast<uint8_t*>(msg.data.data()), msg.step);
  cv::Mat pixels;
  if (msg.encoding == "rgb8") {
    cv::cvtColor(view, pixels, cv::COLOR_RGB2BGR);
  } else {
    pixels = view.clone();
  }
  return pixels;
}

}  // namespace monomap
