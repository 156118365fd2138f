# FindKfdRos2Files: what kfd's ROS 2 log stores need (rosbag2 and MCAP, read and written by kfd
# itself: no rosbag2 or MCAP library is packaged for Debian 12): sqlite3 (libsqlite3-dev, rosbag2's
# .db3), yaml-cpp (libyaml-cpp-dev, rosbag2's metadata.yaml), zstd and lz4 (libzstd-dev,
# liblz4-dev: MCAP's chunk compressions).
#
# Defines the imported target KfdRos2Files::deps.
find_path(KfdRos2Files_SQLITE_INCLUDE sqlite3.h)
find_library(KfdRos2Files_SQLITE_LIB sqlite3)
find_path(KfdRos2Files_YAML_INCLUDE yaml-cpp/yaml.h)
find_library(KfdRos2Files_YAML_LIB yaml-cpp)
find_path(KfdRos2Files_ZSTD_INCLUDE zstd.h)
find_library(KfdRos2Files_ZSTD_LIB zstd)
find_path(KfdRos2Files_LZ4_INCLUDE lz4frame.h)
find_library(KfdRos2Files_LZ4_LIB lz4)

include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(KfdRos2Files
  REQUIRED_VARS KfdRos2Files_SQLITE_INCLUDE KfdRos2Files_SQLITE_LIB KfdRos2Files_YAML_INCLUDE
                KfdRos2Files_YAML_LIB KfdRos2Files_ZSTD_INCLUDE KfdRos2Files_ZSTD_LIB
                KfdRos2Files_LZ4_INCLUDE KfdRos2Files_LZ4_LIB
  REASON_FAILURE_MESSAGE
    "Debian: apt-get install libsqlite3-dev libyaml-cpp-dev libzstd-dev liblz4-dev")

if(KfdRos2Files_FOUND AND NOT TARGET KfdRos2Files::deps)
  add_library(KfdRos2Files::deps INTERFACE IMPORTED)
  set_target_properties(KfdRos2Files::deps PROPERTIES
    INTERFACE_INCLUDE_DIRECTORIES "${KfdRos2Files_SQLITE_INCLUDE};${KfdRos2Files_YAML_INCLUDE};${KfdRos2Files_ZSTD_INCLUDE};${KfdRos2Files_LZ4_INCLUDE}"
    INTERFACE_LINK_LIBRARIES "${KfdRos2Files_SQLITE_LIB};${KfdRos2Files_YAML_LIB};${KfdRos2Files_ZSTD_LIB};${KfdRos2Files_LZ4_LIB}")
endif()
