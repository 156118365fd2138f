// kfd_ros2's transport: one Fast DDS participant that speaks ROS 2 as rmw_fastrtps does (topic
// "rt/<name>", type "<pkg>::msg::dds_::<Type>_", XCDR1 samples, no type information, the type
// hash in USER_DATA), carrying samples as CDR bytes: kfd encodes and decodes them itself
// (kfd/io/ros2_message.h), so the bus knows no message layout.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "kfd/ros2/node_params.h"

namespace kfd::ros2 {

/// One endpoint's QoS (keep-last `depth`).
struct TopicQos {
    Reliability reliability = Reliability::Reliable;
    bool transient_local = false;  // tf_static's latching
    int depth = 10;
};

/// A DDS error (the participant, a topic or an endpoint could not be made).
class DdsError : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

class DdsBus {
  public:
    struct Params {
        int domain_id = 0;
        bool localhost_only = false;  // UDP on 127.0.0.1 only, as ROS_LOCALHOST_ONLY=1
        std::string name = "kfd";     // the participant's name
    };
    using Handler = std::function<void(const std::uint8_t* data, std::size_t size)>;

    explicit DdsBus(const Params& p);
    ~DdsBus();
    DdsBus(const DdsBus&) = delete;
    DdsBus& operator=(const DdsBus&) = delete;

    /// Calls `handler` with each sample of `dds_topic` (on a DDS thread). `ros2_type`:
    /// "sensor_msgs/msg/LaserScan" and the like.
    void subscribe(const std::string& dds_topic, const std::string& ros2_type, const TopicQos& qos,
                   Handler handler);
    /// A writer on `dds_topic`; returns its index for publish().
    std::size_t advertise(const std::string& dds_topic, const std::string& ros2_type,
                          const TopicQos& qos);
    /// Writes one sample (CDR with its encapsulation header); false when DDS refused it.
    bool publish(std::size_t writer, const std::vector<std::uint8_t>& cdr);
    /// Readers matched with a writer (tests wait for them; bounded).
    std::size_t matchedReaders(std::size_t writer) const;
    /// Waits until every reliable reader has acknowledged what `writer` wrote, at most
    /// `seconds`; false on timeout.
    bool waitForAcknowledgments(std::size_t writer, double seconds);

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace kfd::ros2
