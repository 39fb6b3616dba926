// monomap_localization_node: localizes a camera on a robot in a monomap
// map (docs/ros.md). Exit codes as `monomap`'s: 1 the map does not load,
// 2 bad parameters, 3 runtime error.
#include <ros/ros.h>

#include <memory>

#include "monomap/io/map_format.h"
#include "monomap/util/error.h"
#include "ros/localization_node.h"

int main(int argc, char** argv) {
  using namespace monomap;
  ros::init(argc, argv, "monomap_localization");
  ros::NodeHandle nh, pnh("~");
  ros_adapter::NodeOptions options;
  try {
    options = ros_adapter::ReadNodeOptions(pnh);
  } catch (const Error& e) {
    ROS_FATAL("bad parameter: %s", e.what());
    return 2;
  }
  std::shared_ptr<const Map> map;
  try {
    map = std::make_shared<const Map>(ReadMap(options.map_dir));
  } catch (const Error& e) {
    ROS_FATAL("cannot load the map '%s': %s", options.map_dir.c_str(),
              e.what());
    return 1;
  }
  try {
    ros_adapter::LocalizationNode node(nh, pnh, options, map);
    ROS_INFO("map '%s': %zu planes; waiting for images",
             options.map_dir.c_str(), map->planes.size());
    ros::spin();
  } catch (const std::exception& e) {
    ROS_FATAL("%s", e.what());
    return 3;
  }
  return 0;
}
