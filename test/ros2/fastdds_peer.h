// An independent ROS 2 peer for kfd_ros2's tests: a Fast DDS participant set up as rmw_fastrtps
// sets itself up (types registered without type information, XCDR1 samples, 127.0.0.1 only as
// ROS_LOCALHOST_ONLY=1), whose messages are encoded and decoded with eProsima's Fast CDR
// (field by field, as rosidl's generated type support does), not with kfd's CDR code.
#pragma once

#include <fastcdr/Cdr.h>
#include <fastcdr/FastBuffer.h>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastrtps/utils/IPLocator.h>
#include <nav_msgs/Odometry.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2_msgs/TFMessage.h>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/TopicDataType.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include <chrono>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace kfd_test {

namespace dds = eprosima::fastdds::dds;
using eprosima::fastcdr::Cdr;

inline void put(Cdr& c, const std_msgs::Header& h) {
    c << static_cast<std::int32_t>(h.stamp.sec) << h.stamp.nsec << h.frame_id;
}
inline void get(Cdr& c, std_msgs::Header& h) {
    std::int32_t sec = 0;
    c >> sec >> h.stamp.nsec >> h.frame_id;
    h.stamp.sec = static_cast<std::uint32_t>(sec);
}
inline void put(Cdr& c, const sensor_msgs::LaserScan& m) {
    put(c, m.header);
    c << m.angle_min << m.angle_max << m.angle_increment << m.time_increment << m.scan_time
      << m.range_min << m.range_max << m.ranges << m.intensities;
}
inline void get(Cdr& c, sensor_msgs::LaserScan& m) {
    get(c, m.header);
    c >> m.angle_min >> m.angle_max >> m.angle_increment >> m.time_increment >> m.scan_time >>
        m.range_min >> m.range_max >> m.ranges >> m.intensities;
}
inline void put(Cdr& c, const nav_msgs::Odometry& m) {
    put(c, m.header);
    c << m.child_frame_id;
    const auto& p = m.pose.pose;
    c << p.position.x << p.position.y << p.position.z;
    c << p.orientation.x << p.orientation.y << p.orientation.z << p.orientation.w;
    for (double v : m.pose.covariance) c << v;
    const auto& t = m.twist.twist;
    c << t.linear.x << t.linear.y << t.linear.z << t.angular.x << t.angular.y << t.angular.z;
    for (double v : m.twist.covariance) c << v;
}
inline void get(Cdr&, nav_msgs::Odometry&) {}  // the peer only publishes odometry
inline void put(Cdr& c, const tf2_msgs::TFMessage& m) {
    c << static_cast<std::uint32_t>(m.transforms.size());
    for (const auto& t : m.transforms) {
        put(c, t.header);
        c << t.child_frame_id;
        const auto& tr = t.transform;
        c << tr.translation.x << tr.translation.y << tr.translation.z;
        c << tr.rotation.x << tr.rotation.y << tr.rotation.z << tr.rotation.w;
    }
}
inline void get(Cdr&, tf2_msgs::TFMessage&) {}

/// A ROS 2 message type serialized with Fast CDR (T: a ROS 1 message struct of the same fields).
template <class T>
class FastCdrType : public dds::TopicDataType {
  public:
    explicit FastCdrType(const std::string& dds_name) {
        setName(dds_name.c_str());
        m_typeSize = 4 + 65536;
        m_isGetKeyDefined = false;
        auto_fill_type_information(false);
        auto_fill_type_object(false);
    }
    bool serialize(void* data, eprosima::fastrtps::rtps::SerializedPayload_t* p) override {
        eprosima::fastcdr::FastBuffer fb(reinterpret_cast<char*>(p->data), p->max_size);
        Cdr c(fb, Cdr::DEFAULT_ENDIAN, Cdr::DDS_CDR);
        p->encapsulation = c.endianness() == Cdr::BIG_ENDIANNESS ? CDR_BE : CDR_LE;
        try {
            c.serialize_encapsulation();
            put(c, *static_cast<T*>(data));
        } catch (const std::exception&) {
            return false;
        }
        p->length = static_cast<std::uint32_t>(c.getSerializedDataLength());
        return true;
    }
    bool deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* p, void* data) override {
        eprosima::fastcdr::FastBuffer fb(reinterpret_cast<char*>(p->data), p->length);
        Cdr c(fb, Cdr::DEFAULT_ENDIAN, Cdr::DDS_CDR);
        try {
            c.read_encapsulation();
            get(c, *static_cast<T*>(data));
        } catch (const std::exception&) {
            return false;
        }
        return true;
    }
    std::function<std::uint32_t()> getSerializedSizeProvider(void* data) override {
        return [data] {  // a bound: a ROS 2 message's CDR is never larger
            eprosima::fastcdr::FastBuffer fb;
            Cdr c(fb, Cdr::DEFAULT_ENDIAN, Cdr::DDS_CDR);
            c.serialize_encapsulation();
            put(c, *static_cast<T*>(data));
            return static_cast<std::uint32_t>(c.getSerializedDataLength() + 8);
        };
    }
    void* createData() override { return new T(); }
    void deleteData(void* d) override { delete static_cast<T*>(d); }
    bool getKey(void*, eprosima::fastrtps::rtps::InstanceHandle_t*, bool) override { return false; }
};

/// One participant on `domain`, 127.0.0.1 only.
class FastDdsPeer {
  public:
    explicit FastDdsPeer(int domain) {
        dds::DomainParticipantQos q;
        q.name("kfd_test_peer");
        auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
        udp->interfaceWhiteList.emplace_back("127.0.0.1");
        udp->receiveBufferSize = 1u << 21;  // 2 MiB: a burst of scans is not dropped by the OS
        udp->sendBufferSize = 1u << 21;
        q.transport().user_transports.push_back(udp);
        q.transport().use_builtin_transports = false;
        eprosima::fastrtps::rtps::Locator_t peer;
        eprosima::fastrtps::rtps::IPLocator::setIPv4(peer, 127, 0, 0, 1);
        q.wire_protocol().builtin.initialPeersList.push_back(peer);
        participant_ = dds::DomainParticipantFactory::get_instance()->create_participant(domain, q);
        publisher_ = participant_->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
        subscriber_ = participant_->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
    }
    ~FastDdsPeer() {
        for (auto* r : readers_) r->set_listener(nullptr);
        participant_->delete_contained_entities();
        dds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
    }

    template <class T>
    dds::DataWriter* writer(const std::string& topic, const std::string& type, bool reliable,
                            bool transient_local = false) {
        dds::DataWriterQos q = dds::DATAWRITER_QOS_DEFAULT;
        q.reliability().kind =
            reliable ? dds::RELIABLE_RELIABILITY_QOS : dds::BEST_EFFORT_RELIABILITY_QOS;
        q.durability().kind =
            transient_local ? dds::TRANSIENT_LOCAL_DURABILITY_QOS : dds::VOLATILE_DURABILITY_QOS;
        q.history().kind = dds::KEEP_ALL_HISTORY_QOS;
        q.endpoint().history_memory_policy =
            eprosima::fastrtps::rtps::PREALLOCATED_WITH_REALLOC_MEMORY_MODE;
        q.publish_mode().kind = dds::ASYNCHRONOUS_PUBLISH_MODE;
        return publisher_->create_datawriter(topicOf<T>(topic, type), q);
    }

    /// A reliable keep-all reader of `topic`; `on` gets each sample (a DDS thread).
    template <class T>
    void reader(const std::string& topic, const std::string& type, std::function<void(T&)> on) {
        struct L : dds::DataReaderListener {
            std::function<void(T&)> f;
            void on_data_available(dds::DataReader* r) override {
                T m;
                dds::SampleInfo info;
                while (r->take_next_sample(&m, &info) == ReturnCode_t::RETCODE_OK)
                    if (info.valid_data) f(m);
            }
        };
        auto* l = new L();
        l->f = std::move(on);
        listeners_.emplace_back(l);
        dds::DataReaderQos q = dds::DATAREADER_QOS_DEFAULT;
        q.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
        q.history().kind = dds::KEEP_ALL_HISTORY_QOS;
        q.endpoint().history_memory_policy =
            eprosima::fastrtps::rtps::PREALLOCATED_WITH_REALLOC_MEMORY_MODE;
        readers_.push_back(subscriber_->create_datareader(topicOf<T>(topic, type), q, l));
    }

  private:
    template <class T>
    dds::Topic* topicOf(const std::string& name, const std::string& type) {
        if (!participant_->find_type(type).get())
            dds::TypeSupport(new FastCdrType<T>(type)).register_type(participant_);
        return participant_->create_topic(name, type, dds::TOPIC_QOS_DEFAULT);
    }
    dds::DomainParticipant* participant_ = nullptr;
    dds::Publisher* publisher_ = nullptr;
    dds::Subscriber* subscriber_ = nullptr;
    std::vector<dds::DataReader*> readers_;
    std::vector<std::unique_ptr<dds::DataReaderListener>> listeners_;
};

/// Waits (at most `seconds`) until `ready()`; whether it came.
inline bool waitUntil(double seconds, const std::function<bool()>& ready) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (!ready()) {
        if (std::chrono::steady_clock::now() > end) return false;
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return true;
}

inline std::size_t matched(dds::DataWriter* w) {
    dds::PublicationMatchedStatus s;
    w->get_publication_matched_status(s);
    return static_cast<std::size_t>(s.current_count);
}

}  // namespace kfd_test
