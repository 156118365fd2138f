#include "kfd/ros2/dds_bus.h"

#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastrtps/utils/IPLocator.h>
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

#include <cstring>
#include <map>

#include "kfd/ros2/type_hash.h"

namespace kfd::ros2 {

namespace dds = eprosima::fastdds::dds;
using Bytes = std::vector<std::uint8_t>;

namespace {

// A ROS 2 message type whose samples are the CDR bytes themselves (encapsulation included):
// what rmw_fastrtps's type support writes, without knowing the fields.
class CdrBytesType : public dds::TopicDataType {
  public:
    explicit CdrBytesType(const std::string& dds_name) {
        setName(dds_name.c_str());
        m_typeSize = 4 + 65536;
        m_isGetKeyDefined = false;
        auto_fill_type_information(false);  // as rmw_fastrtps: ROS 2 sends no type object
        auto_fill_type_object(false);
    }
    bool serialize(void* data, eprosima::fastrtps::rtps::SerializedPayload_t* payload) override {
        const Bytes& b = *static_cast<const Bytes*>(data);
        if (b.size() < 4 || b.size() > payload->max_size) return false;
        std::memcpy(payload->data, b.data(), b.size());
        payload->length = static_cast<std::uint32_t>(b.size());
        payload->encapsulation = b[1] == 1 ? CDR_LE : CDR_BE;
        return true;
    }
    bool deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload, void* data) override {
        Bytes& b = *static_cast<Bytes*>(data);
        b.assign(payload->data, payload->data + payload->length);
        return true;
    }
    std::function<std::uint32_t()> getSerializedSizeProvider(void* data) override {
        return [data] { return static_cast<std::uint32_t>(static_cast<Bytes*>(data)->size()); };
    }
    void* createData() override { return new Bytes(); }
    void deleteData(void* data) override { delete static_cast<Bytes*>(data); }
    bool getKey(void*, eprosima::fastrtps::rtps::InstanceHandle_t*, bool) override { return false; }
};

class Listener : public dds::DataReaderListener {
  public:
    explicit Listener(DdsBus::Handler h) : handler_(std::move(h)) {}
    void on_data_available(dds::DataReader* reader) override {
        Bytes sample;
        dds::SampleInfo info;
        while (reader->take_next_sample(&sample, &info) == ReturnCode_t::RETCODE_OK)
            if (info.valid_data) handler_(sample.data(), sample.size());
    }

  private:
    DdsBus::Handler handler_;
};

template <class Qos>
void applyQos(Qos& q, const TopicQos& t, const std::string& ros2_type) {
    q.reliability().kind = t.reliability == Reliability::Reliable
                               ? dds::RELIABLE_RELIABILITY_QOS
                               : dds::BEST_EFFORT_RELIABILITY_QOS;
    q.durability().kind =
        t.transient_local ? dds::TRANSIENT_LOCAL_DURABILITY_QOS : dds::VOLATILE_DURABILITY_QOS;
    q.history().kind = dds::KEEP_LAST_HISTORY_QOS;
    q.history().depth = t.depth;
    q.endpoint().history_memory_policy =
        eprosima::fastrtps::rtps::PREALLOCATED_WITH_REALLOC_MEMORY_MODE;
    const std::string user = "typehash=" + typeHash(ros2_type) + ";";
    q.user_data().setValue(std::vector<eprosima::fastrtps::rtps::octet>(user.begin(), user.end()));
}

}  // namespace

struct DdsBus::Impl {
    dds::DomainParticipant* participant = nullptr;
    dds::Publisher* publisher = nullptr;
    dds::Subscriber* subscriber = nullptr;
    std::map<std::string, dds::Topic*> topics;
    std::vector<dds::DataWriter*> writers;
    std::vector<std::pair<dds::DataReader*, std::unique_ptr<Listener>>> readers;

    dds::Topic* topic(const std::string& name, const std::string& ros2_type) {
        if (const auto it = topics.find(name); it != topics.end()) return it->second;
        const std::string type = ddsTypeName(ros2_type);
        if (!participant->find_type(type).get()) {
            dds::TypeSupport ts(new CdrBytesType(type));
            if (ts.register_type(participant) != ReturnCode_t::RETCODE_OK)
                throw DdsError("cannot register the DDS type " + type);
        }
        dds::Topic* t = participant->create_topic(name, type, dds::TOPIC_QOS_DEFAULT);
        if (!t) throw DdsError("cannot create the DDS topic " + name + " (" + type + ")");
        topics[name] = t;
        return t;
    }
};

DdsBus::DdsBus(const Params& p) : impl_(std::make_unique<Impl>()) {
    dds::DomainParticipantQos q;
    q.name(p.name);
    if (p.localhost_only) {  // as rmw_fastrtps with ROS_LOCALHOST_ONLY=1, and a unicast peer
        auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
        udp->interfaceWhiteList.emplace_back("127.0.0.1");
        udp->receiveBufferSize = 1u << 21;  // 2 MiB: a burst of scans is not dropped by the OS
        udp->sendBufferSize = 1u << 21;
        q.transport().user_transports.push_back(udp);
        q.transport().use_builtin_transports = false;
        eprosima::fastrtps::rtps::Locator_t peer;
        eprosima::fastrtps::rtps::IPLocator::setIPv4(peer, 127, 0, 0, 1);
        q.wire_protocol().builtin.initialPeersList.push_back(peer);
    }
    impl_->participant = dds::DomainParticipantFactory::get_instance()->create_participant(
        static_cast<dds::DomainId_t>(p.domain_id), q);
    if (!impl_->participant)
        throw DdsError("cannot create a DDS participant on domain " + std::to_string(p.domain_id));
    impl_->publisher = impl_->participant->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
    impl_->subscriber = impl_->participant->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
    if (!impl_->publisher || !impl_->subscriber) throw DdsError("cannot create a DDS publisher");
}

DdsBus::~DdsBus() {
    if (!impl_->participant) return;
    for (auto& [reader, listener] : impl_->readers) reader->set_listener(nullptr);
    impl_->participant->delete_contained_entities();
    dds::DomainParticipantFactory::get_instance()->delete_participant(impl_->participant);
}

void DdsBus::subscribe(const std::string& dds_topic, const std::string& ros2_type,
                       const TopicQos& qos, Handler handler) {
    dds::DataReaderQos q = dds::DATAREADER_QOS_DEFAULT;
    applyQos(q, qos, ros2_type);
    auto listener = std::make_unique<Listener>(std::move(handler));
    dds::DataReader* r =
        impl_->subscriber->create_datareader(impl_->topic(dds_topic, ros2_type), q, listener.get());
    if (!r) throw DdsError("cannot subscribe to " + dds_topic);
    impl_->readers.emplace_back(r, std::move(listener));
}

std::size_t DdsBus::advertise(const std::string& dds_topic, const std::string& ros2_type,
                              const TopicQos& qos) {
    dds::DataWriterQos q = dds::DATAWRITER_QOS_DEFAULT;
    applyQos(q, qos, ros2_type);
    q.publish_mode().kind = dds::SYNCHRONOUS_PUBLISH_MODE;
    dds::DataWriter* w = impl_->publisher->create_datawriter(impl_->topic(dds_topic, ros2_type), q);
    if (!w) throw DdsError("cannot publish on " + dds_topic);
    impl_->writers.push_back(w);
    return impl_->writers.size() - 1;
}

bool DdsBus::publish(std::size_t writer, const Bytes& cdr) {
    return impl_->writers.at(writer)->write(const_cast<Bytes*>(&cdr));
}

std::size_t DdsBus::matchedReaders(std::size_t writer) const {
    dds::PublicationMatchedStatus s;
    impl_->writers.at(writer)->get_publication_matched_status(s);
    return static_cast<std::size_t>(s.current_count);
}

bool DdsBus::waitForAcknowledgments(std::size_t writer, double seconds) {
    return impl_->writers.at(writer)->wait_for_acknowledgments(
               eprosima::fastrtps::Duration_t(seconds)) == ReturnCode_t::RETCODE_OK;
}

}  // namespace kfd::ros2
