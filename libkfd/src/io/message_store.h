// A log of ROS messages whatever its container: a ROS 1 bag, a rosbag2 sqlite3 bag (a folder
// with metadata.yaml, or one .db3) or an MCAP file. The bag source reads any of them through
// this door; each store lists its topics and walks its messages in time order. Private to
// libkfd.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <string>

#include "bag_message.h"

namespace kfd {

/// One topic of a store: its type as the file names it ("sensor_msgs/LaserScan" in ROS 1,
/// "sensor_msgs/msg/LaserScan" in ROS 2), its messages and their first and last times (s).
struct TopicInfo {
    std::string type;
    std::size_t count = 0;
    double first = 0.0, last = 0.0;
};

class MessageStore {
  public:
    class Cursor {
      public:
        virtual ~Cursor() = default;
        /// The next message into `out`; false at the end. BagError (or BagFileError) naming the
        /// file when the store cannot be read there.
        virtual bool next(NativeMessage& out) = 0;
        /// The messages this cursor goes over.
        virtual std::size_t size() const = 0;
    };

    virtual ~MessageStore() = default;
    virtual std::map<std::string, TopicInfo> topics() = 0;
    /// The messages of one topic, or of all ("") in time order. `consuming`: the one pass that
    /// reads the whole log (a store may free what that pass has read).
    virtual std::unique_ptr<Cursor> cursor(const std::string& topic, bool consuming) = 0;
    /// "ROS 1 bag", "rosbag2 (sqlite3)", "MCAP": for listings.
    virtual std::string kind() const = 0;
    /// The compression of the store's data ("none", "bz2", "lz4", "zstd"; of most of it).
    virtual std::string compression() const = 0;
    /// ROS 1 bags: the chunks, and how many have been loaded so far (BagSource::chunks()).
    virtual std::size_t chunks() const { return 0; }
    virtual std::size_t chunksLoaded() const { return 0; }
};

/// The store of the log at `path` (LogFormat Bag, Rosbag2 or Mcap, told by content). `check`:
/// check the whole file's structure now (a listing); otherwise each part is checked as it is
/// read. BagError naming the file and the reason.
std::unique_ptr<MessageStore> openMessageStore(const std::string& path, bool check);

/// True when a type as a store names it is `ros1_type` ("sensor_msgs/LaserScan"), in either
/// ROS's spelling.
bool isType(const std::string& type, const char* ros1_type);

}  // namespace kfd
