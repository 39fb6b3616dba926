// Decoders of the ROS 2 messages the bag importer reads, from their CDR
// serialization as rosbag2 stores it (4-byte encapsulation header, then
// XCDR1 plain CDR, little- or big-endian, with alignment counted from the
// end of the header). Built over Debian's libfastcdr.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "monomap/io/bag_import.h"

namespace monomap::ros2 {

// Each decoder reads one serialized message of `size` bytes. `recorded` is
// the time (s) the bag recorded it, used when the header stamp is zero.
// Throws InputError naming `where` (the file and topic) and the field for a
// truncated or corrupt message or an encapsulation other than plain CDR.

// sensor_msgs/msg/Image (compressed = false) or CompressedImage.
bag::Image DecodeImage(const uint8_t* data, size_t size, bool compressed,
                       double recorded, const std::string& where);
// sensor_msgs/msg/CameraInfo.
bag::CameraInfo DecodeCameraInfo(const uint8_t* data, size_t size,
                                 const std::string& where);
// tf2_msgs/msg/TFMessage: its transforms.
std::vector<bag::Transform> DecodeTfMessage(const uint8_t* data, size_t size,
                                            double recorded,
                                            const std::string& where);
// nav_msgs/msg/Odometry: the pose (parent = header.frame_id, child =
// child_frame_id).
bag::Transform DecodeOdometry(const uint8_t* data, size_t size, double recorded,
                              const std::string& where);

}  // namespace monomap::ros2
