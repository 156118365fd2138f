# FindKfdRos1: Debian's ROS 1 bag libraries (librosbag-storage-dev, libroslz4-dev) and the
# message headers kfd reads (libsensor-msgs-dev, libnav-msgs-dev, libtf2-msgs-dev); libbz2 for kfd's
# own check of a bag's chunks (libbz2-dev, a dependency of librosbag-storage-dev).
#
# Debian 12's catkin package configs cannot be used from a plain CMake project (rosbag_storage's
# pkg-config file requires a pluginlib.pc that is not shipped, and pluginlib's CMake config runs
# ament's Python tooling), so the headers and libraries are found directly. rosbag/bag.h
# includes pluginlib, whose headers live one level down (/usr/include/<pkg>/<pkg>/...).
#
# Defines the imported target KfdRos1::rosbag.
find_path(KfdRos1_INCLUDE_DIR rosbag/bag.h)
find_path(KfdRos1_SENSOR_MSGS_DIR sensor_msgs/LaserScan.h)
find_path(KfdRos1_NAV_MSGS_DIR nav_msgs/Odometry.h)
find_path(KfdRos1_TF2_MSGS_DIR tf2_msgs/TFMessage.h)
include(${CMAKE_CURRENT_LIST_DIR}/KfdRosFind.cmake)
set(_kfd_ros1_nested)  # optional: the headers rosbag/bag.h includes through pluginlib
kfd_ros_find_nested(KfdRos1 _kfd_ros1_nested "pluginlib:pluginlib/class_loader.hpp"
  "class_loader:class_loader/multi_library_class_loader.hpp"
  "rcpputils:rcpputils/shared_library.hpp" "rcutils:rcutils/types.h"
  "ament_index_cpp:ament_index_cpp/get_package_prefix.hpp")
set(_kfd_ros1_libs)
kfd_ros_find_libs(KfdRos1 _kfd_ros1_libs
  rosbag_storage roslz4 rostime cpp_common roscpp_serialization console_bridge bz2)
find_package(Boost QUIET COMPONENTS filesystem)

include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(KfdRos1
  REQUIRED_VARS KfdRos1_INCLUDE_DIR KfdRos1_SENSOR_MSGS_DIR KfdRos1_NAV_MSGS_DIR
                KfdRos1_TF2_MSGS_DIR ${_kfd_ros1_libs} Boost_FOUND
  REASON_FAILURE_MESSAGE
    "Debian: apt-get install librosbag-storage-dev libroslz4-dev libsensor-msgs-dev libnav-msgs-dev libtf2-msgs-dev")

if(KfdRos1_FOUND AND NOT TARGET KfdRos1::rosbag)
  add_library(KfdRos1::rosbag INTERFACE IMPORTED)
  kfd_ros_values(_kfd_ros1_link ${_kfd_ros1_libs})
  kfd_ros_values(_kfd_ros1_nested_dirs ${_kfd_ros1_nested})
  set_target_properties(KfdRos1::rosbag PROPERTIES
    INTERFACE_INCLUDE_DIRECTORIES "${KfdRos1_INCLUDE_DIR};${KfdRos1_SENSOR_MSGS_DIR};${KfdRos1_NAV_MSGS_DIR};${KfdRos1_TF2_MSGS_DIR};${_kfd_ros1_nested_dirs}"
    INTERFACE_LINK_LIBRARIES "${_kfd_ros1_link};Boost::filesystem")
endif()
