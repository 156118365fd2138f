# FindKfdRosNode: what kfd's ROS 1 node and nodelet (kfd_node, kfd/FilterNodelet) need from
# Debian's ROS 1 packages: roscpp (libroscpp-dev), tf2_ros (libtf2-ros-dev), nodelet
# (libnodeletlib-dev, with pluginlib-dev's class_list_macros), diagnostic_msgs
# (libdiagnostic-msgs-dev), std_msgs, sensor_msgs and nav_msgs headers.
#
# As in FindKfdRos1.cmake, the headers and libraries are found directly: Debian 12's nodelet
# CMake config loads pluginlib's, which runs ament's Python tooling (not installed). roscpp's own
# config is plain catkin and is used for its library list.
#
# Optional: when something is missing, KfdRosNode_FOUND is false and the node is not built.
# Defines the imported target KfdRosNode::ros.
find_package(roscpp QUIET)
find_path(KfdRosNode_TF2_ROS_DIR tf2_ros/transform_listener.h)
find_path(KfdRosNode_NODELET_DIR nodelet/nodelet.h)
find_path(KfdRosNode_DIAGNOSTIC_MSGS_DIR diagnostic_msgs/DiagnosticArray.h)
find_path(KfdRosNode_STD_MSGS_DIR std_msgs/Header.h)
# The nodelet's plugin macros: pluginlib and class_loader (ROS 2 era in Debian 12, with rcpputils
# and rcutils), whose headers live one level down (/usr/include/<pkg>/<pkg>/...).
include(${CMAKE_CURRENT_LIST_DIR}/KfdRosFind.cmake)
set(_kfd_node_nested)
kfd_ros_find_nested(KfdRosNode _kfd_node_nested "pluginlib:pluginlib/class_list_macros.hpp"
  "class_loader:class_loader/class_loader.hpp" "rcpputils:rcpputils/shared_library.hpp"
  "rcutils:rcutils/types.h")
set(_kfd_node_libs)
kfd_ros_find_libs(KfdRosNode _kfd_node_libs
  tf2_ros tf2 message_filters actionlib nodeletlib bondcpp class_loader rcpputils rcutils)

include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(KfdRosNode
  REQUIRED_VARS roscpp_FOUND KfdRosNode_TF2_ROS_DIR KfdRosNode_NODELET_DIR
                KfdRosNode_DIAGNOSTIC_MSGS_DIR KfdRosNode_STD_MSGS_DIR ${_kfd_node_nested}
                ${_kfd_node_libs}
  REASON_FAILURE_MESSAGE
    "Debian: apt-get install libroscpp-dev libtf2-ros-dev libnodeletlib-dev pluginlib-dev libdiagnostic-msgs-dev libstd-msgs-dev")

if(KfdRosNode_FOUND AND NOT TARGET KfdRosNode::ros)
  add_library(KfdRosNode::ros INTERFACE IMPORTED)
  kfd_ros_values(_kfd_node_nested_dirs ${_kfd_node_nested})
  kfd_ros_values(_kfd_node_link ${_kfd_node_libs})
  set(_kfd_node_inc ${roscpp_INCLUDE_DIRS} ${KfdRosNode_TF2_ROS_DIR} ${KfdRosNode_NODELET_DIR}
                    ${KfdRosNode_DIAGNOSTIC_MSGS_DIR} ${_kfd_node_nested_dirs})
  set_target_properties(KfdRosNode::ros PROPERTIES
    INTERFACE_INCLUDE_DIRECTORIES "${_kfd_node_inc}"
    INTERFACE_LINK_LIBRARIES "${_kfd_node_link};${roscpp_LIBRARIES}")
endif()
