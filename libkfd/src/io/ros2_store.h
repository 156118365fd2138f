// The ROS 2 log stores: rosbag2 (sqlite3, a folder or a .db3) and MCAP. Private to libkfd.
#pragma once

#include <memory>
#include <string>

#include "message_store.h"

namespace kfd {

/// A rosbag2 folder (metadata.yaml and its files: sqlite3, or one MCAP) or one .db3 file.
/// Compressed rosbag2 (file or message mode) is refused, naming `ros2 bag decompress`.
std::unique_ptr<MessageStore> openRosbag2(const std::string& path);
/// An MCAP file; `check` walks every record (and chunk) when it is opened.
std::unique_ptr<MessageStore> openMcap(const std::string& path, bool check);

}  // namespace kfd
