// The stores of ROS logs: a ROS 1 bag (kfd's structure check, rosbag_storage's index, kfd's
// chunk reader), and the ROS 2 ones (ros2_store.h); openMessageStore picks one by content.
#include "message_store.h"

#include <rosbag/bag.h>
#include <rosbag/view.h>

#include <filesystem>

#include "bag_file.h"
#include "bag_reader.h"
#include "kfd/io/open_source.h"
#include "kfd/io/ros2_message.h"
#include "ros2_store.h"

namespace kfd {
namespace {

namespace fs = std::filesystem;

// A ROS 1 bag open for reading: its structure checked by kfd (BagFile::check; its chunks'
// records there when `check_chunks`, else as the reader loads them), its index read by
// rosbag_storage, its messages read through a BagReader.
class Ros1Store : public MessageStore {
  public:
    Ros1Store(const std::string& path, bool check_chunks) {
        std::error_code ec;
        if (!fs::is_regular_file(path, ec)) throw BagError(path + ": no such file", path);
        file_ = std::make_unique<BagFile>(path);
        file_->check(check_chunks);
        try {
            bag_.open(path, rosbag::bagmode::Read);
        } catch (const std::exception& e) {
            throw BagError(path + ": not a readable ROS 1 bag (" + e.what() +
                               "; a bag cut short while recording has no index: `rosbag "
                               "reindex` repairs it)",
                           path);
        }
        reader_ = std::make_unique<BagReader>(*file_, bag_);
    }

    // The bag's topics, from its index only.
    std::map<std::string, TopicInfo> topics() override {
        std::map<std::string, TopicInfo> topics;
        rosbag::View all(bag_);
        for (const rosbag::ConnectionInfo* c : all.getConnections())
            topics[c->topic].type = c->datatype;
        for (auto& [name, info] : topics) {
            rosbag::View v(bag_, rosbag::TopicQuery(name));
            info.count = v.size();
            if (info.count) {
                info.first = v.getBeginTime().toSec();
                info.last = v.getEndTime().toSec();
            }
        }
        return topics;
    }

    std::unique_ptr<Cursor> cursor(const std::string& topic, bool consuming) override {
        return std::make_unique<Ros1Cursor>(reader_->cursor(topic, consuming));
    }
    std::string kind() const override { return "ROS 1 bag"; }
    std::string compression() const override { return file_->compression(); }
    std::size_t chunks() const override { return reader_->chunks(); }
    std::size_t chunksLoaded() const override { return reader_->chunksLoaded(); }

  private:
    class Ros1Cursor : public Cursor {
      public:
        explicit Ros1Cursor(BagReader::Cursor c) : c_(std::move(c)) {}
        bool next(NativeMessage& out) override {
            out.ros2 = nullptr;
            out.time_ns = 0;
            return c_.next(out);
        }
        std::size_t size() const override { return c_.size(); }

      private:
        BagReader::Cursor c_;
    };

    std::unique_ptr<BagFile> file_;
    rosbag::Bag bag_;
    std::unique_ptr<BagReader> reader_;
};

}  // namespace

std::unique_ptr<MessageStore> openMessageStore(const std::string& path, bool check) {
    LogFormat format;
    try {
        format = detectFormat(path);
    } catch (const SourceError& e) {
        throw BagError(e.what(), path);
    }
    switch (format) {
        case LogFormat::Rosbag2:
            return openRosbag2(path);
        case LogFormat::Mcap:
            return openMcap(path, check);
        case LogFormat::Bag:
            break;
        default:
            throw BagError(path + ": not a ROS bag, rosbag2 or MCAP file", path);
    }
    return std::make_unique<Ros1Store>(path, check);
}

bool isType(const std::string& type, const char* ros1_type) {
    return ros1TypeName(type) == ros1_type;
}

}  // namespace kfd
