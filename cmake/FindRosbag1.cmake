# Finds ROS 1 bag storage and the message headers `monomap import rosbag`
# needs, as Debian packages them (librosbag-dev, libsensor-msgs-dev,
# libnav-msgs-dev, libtf2-msgs-dev, libgeometry-msgs-dev). Debian's
# rosbag_storage.pc requires a pluginlib.pc it does not ship, so the parts
# are found one by one. Defines Rosbag1_FOUND and the target Rosbag1::Rosbag1.
find_path(Rosbag1_INCLUDE_DIR rosbag/bag.h)
# rosbag/bag.h includes pluginlib and, through it, packages that Debian
# installs one level down (/usr/include/NAME/NAME/...).
set(_rosbag1_nested)
foreach(pkg pluginlib class_loader rcutils rcpputils ament_index_cpp)
  find_path(Rosbag1_${pkg}_INCLUDE_DIR ${pkg} PATH_SUFFIXES ${pkg}
            NO_CACHE NO_DEFAULT_PATH PATHS /usr/include /usr/local/include)
  list(APPEND _rosbag1_nested Rosbag1_${pkg}_INCLUDE_DIR)
endforeach()
find_path(Rosbag1_MSGS_INCLUDE_DIR sensor_msgs/CompressedImage.h
          nav_msgs/Odometry.h tf2_msgs/TFMessage.h)
set(_rosbag1_libs)
foreach(lib rosbag_storage roscpp_serialization rostime cpp_common
            console_bridge)
  find_library(Rosbag1_${lib}_LIBRARY ${lib})
  list(APPEND _rosbag1_libs Rosbag1_${lib}_LIBRARY)
endforeach()
find_package(Boost QUIET COMPONENTS filesystem)
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(Rosbag1 REQUIRED_VARS Rosbag1_INCLUDE_DIR
  ${_rosbag1_nested}  Rosbag1_MSGS_INCLUDE_DIR ${_rosbag1_libs} Boost_FOUND)
if(Rosbag1_FOUND AND NOT TARGET Rosbag1::Rosbag1)
  add_library(Rosbag1::Rosbag1 INTERFACE IMPORTED)
  set(_rosbag1_paths)
  foreach(var ${_rosbag1_libs})
    list(APPEND _rosbag1_paths ${${var}})
  endforeach()
  target_include_directories(Rosbag1::Rosbag1 SYSTEM INTERFACE
    ${Rosbag1_INCLUDE_DIR} ${Rosbag1_MSGS_INCLUDE_DIR})
  foreach(var ${_rosbag1_nested})
    target_include_directories(Rosbag1::Rosbag1 SYSTEM INTERFACE ${${var}})
  endforeach()
  target_link_libraries(Rosbag1::Rosbag1 INTERFACE ${_rosbag1_paths}
                        Boost::filesystem)
endif()
