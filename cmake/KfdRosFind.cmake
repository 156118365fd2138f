# Helpers for FindKfdRos1.cmake and FindKfdRosNode.cmake: Debian 12's ROS 1 catkin configs
# cannot be used from a plain CMake project, so headers and libraries are found one by one.

# kfd_ros_find_nested(PREFIX OUT "pkg:header" ...): headers of ROS 2-era packages Debian ships
# one level down (/usr/include/<pkg>/<pkg>/...). Sets PREFIX_<pkg>_DIR for each and appends
# the variables' names to OUT.
function(kfd_ros_find_nested prefix out)
  set(_names ${${out}})
  foreach(_pair ${ARGN})
    string(REPLACE ":" ";" _pair "${_pair}")
    list(GET _pair 0 _pkg)
    list(GET _pair 1 _file)
    find_path(${prefix}_${_pkg}_DIR ${_file} PATH_SUFFIXES ${_pkg})
    list(APPEND _names ${prefix}_${_pkg}_DIR)
  endforeach()
  set(${out} ${_names} PARENT_SCOPE)
endfunction()

# kfd_ros_find_libs(PREFIX OUT lib ...): sets PREFIX_<lib>_LIBRARY for each and appends the
# variables' names to OUT.
function(kfd_ros_find_libs prefix out)
  set(_names ${${out}})
  foreach(_lib ${ARGN})
    find_library(${prefix}_${_lib}_LIBRARY ${_lib})
    list(APPEND _names ${prefix}_${_lib}_LIBRARY)
  endforeach()
  set(${out} ${_names} PARENT_SCOPE)
endfunction()

# kfd_ros_values(OUT var ...): the found values of the named variables (the NOTFOUND ones left
# out).
function(kfd_ros_values out)
  set(_values)
  foreach(_v ${ARGN})
    if(${_v})
      list(APPEND _values ${${_v}})
    endif()
  endforeach()
  set(${out} ${_values} PARENT_SCOPE)
endfunction()
