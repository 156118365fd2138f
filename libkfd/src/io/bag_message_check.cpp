// checkMessageBytes (bag_message.h): the lengths inside one serialized message, checked
// against the message's size before roscpp's deserializer trusts them. roscpp resizes a string
// or an array to the length it reads, zero-filled, and only then finds the bytes missing
// ("Buffer Overrun"): a LaserScan whose ranges length reads 0x40000000 made it allocate 8.4 GB.
// ROS 1 serialization: little-endian, no padding; a string or a variable-length array is a
// uint32 count followed by its elements; fixed-size arrays and nested messages are inline.
// http://wiki.ros.org/msg#Fields,
// http://wiki.ros.org/ROS/Technical%20Overview#Message_serialization
#include <ros/serialization.h>

#include <cstdint>
#include <string>
#include <vector>

#include "bag_message.h"
#include "kfd/io/bag_source.h"

namespace kfd {
namespace {

// Fixed-size parts, in bytes.
constexpr std::size_t kSeqAndStamp = 4 + 8;                   // std_msgs/Header: seq, stamp
constexpr std::size_t kScanFloats = 7 * 4;                    // angle_min .. range_max
constexpr std::size_t kPoseWithCovariance = 7 * 8 + 36 * 8;   // Pose + float64[36]
constexpr std::size_t kTwistWithCovariance = 6 * 8 + 36 * 8;  // Twist + float64[36]
constexpr std::size_t kTransform = 7 * 8;                     // Vector3 + Quaternion
// The least a geometry_msgs/TransformStamped takes: header (empty frame_id), empty
// child_frame_id, transform.
constexpr std::size_t kMinTransformStamped = kSeqAndStamp + 4 + 4 + kTransform;

// Walks a message's fields in order. Field names are only put together for the message of a
// failure (the walk allocates nothing).
class Walker {
  public:
    Walker(const char* type, const unsigned char* data, std::size_t size)
        : type_(type), data_(data), size_(size) {}

    /// The fields that follow belong to element `i` of the array `name` (nullptr: top level).
    void within(const char* name, std::uint32_t i) {
        array_ = name;
        index_ = i;
    }
    void fixed(std::size_t n, const char* field) {
        if (n > left())
            fail(field, "cut short (" + std::to_string(n) + " bytes needed, " +
                            std::to_string(left()) + " left)");
        pos_ += n;
    }
    // A uint32 count of elements of `element` bytes each (at least that many when `least`);
    // returns the count.
    std::uint32_t count(std::size_t element, const char* field, const char* kind,
                        bool least = false) {
        if (left() < 4)
            fail(field, std::string("cut short (no ") + kind + " length, " +
                            std::to_string(left()) + " bytes left)");
        const unsigned char* p = data_ + pos_;
        pos_ += 4;
        const std::uint32_t n = std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 |
                                std::uint32_t(p[2]) << 16 | std::uint32_t(p[3]) << 24;
        if (n > left() / element) {
            const std::string bytes = std::to_string(std::uint64_t{n} * element);
            fail(field,
                 std::string(kind) + " length " + std::to_string(n) +
                     (element == 1 ? "" : (least ? " (at least " : " (") + bytes + " bytes)") +
                     " does not fit in the message's " + std::to_string(size_) + " bytes (" +
                     std::to_string(left()) + " left)");
        }
        return n;
    }
    void string(const char* field) { pos_ += count(1, field, "string"); }
    void array(std::size_t element, const char* field) {
        pos_ += std::size_t{count(element, field, "array")} * element;
    }
    void header() {
        fixed(kSeqAndStamp, "header");
        string("header.frame_id");
    }

  private:
    std::size_t left() const { return size_ - pos_; }
    [[noreturn]] void fail(const char* field, const std::string& what) const {
        std::string name = array_ ? std::string(array_) + "[" + std::to_string(index_) + "]." : "";
        throw BagError(std::string("corrupt ") + type_ + ": " + name + field + ": " + what);
    }

    const char* type_;
    const unsigned char* data_;
    std::size_t size_, pos_ = 0;
    const char* array_ = nullptr;
    std::uint32_t index_ = 0;
};

}  // namespace

void checkMessageBytes(MessageLayout layout, const unsigned char* data, std::size_t size) {
    switch (layout) {
        case MessageLayout::LaserScan: {
            Walker w("sensor_msgs/LaserScan", data, size);
            w.header();
            w.fixed(kScanFloats, "angle_min..range_max");
            w.array(4, "ranges");
            w.array(4, "intensities");
            break;
        }
        case MessageLayout::Odometry: {
            Walker w("nav_msgs/Odometry", data, size);
            w.header();
            w.string("child_frame_id");
            w.fixed(kPoseWithCovariance, "pose");
            w.fixed(kTwistWithCovariance, "twist");
            break;
        }
        case MessageLayout::TfMessage: {
            Walker w("tf2_msgs/TFMessage", data, size);
            const std::uint32_t n = w.count(kMinTransformStamped, "transforms", "array", true);
            for (std::uint32_t i = 0; i < n; ++i) {
                w.within("transforms", i);
                w.header();
                w.string("child_frame_id");
                w.fixed(kTransform, "transform");
            }
            break;
        }
    }
}

}  // namespace kfd
