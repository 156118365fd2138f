#include "kfd/io/bag_source.h"

#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/poses/CPose3D.h>
#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2_msgs/TFMessage.h>

#include <cmath>
#include <deque>
#include <filesystem>
#include <limits>
#include <map>

#include "bag_file.h"
#include "bag_message.h"
#include "kfd/algorithms/pose.h"
#include "kfd/io/laser_scan.h"
#include "kfd/io/open_source.h"
#include "kfd/pipeline/format.h"
#include "message_store.h"

namespace kfd {
namespace {

namespace fs = std::filesystem;
using mrpt::obs::CObservation2DRangeScan;
using mrpt::obs::CObservationOdometry;

constexpr const char* kLaserScan = "sensor_msgs/LaserScan";
constexpr const char* kMultiEcho = "sensor_msgs/MultiEchoLaserScan";
constexpr const char* kOdometry = "nav_msgs/Odometry";
constexpr const char* kTfMessage = "tf2_msgs/TFMessage";
constexpr double kLookaheadSeconds = 10.0;  // bag time searched for the odometry after a scan
constexpr std::size_t kLookaheadMessages = 100000;
// The bytes of the messages held meanwhile (they are copies: their chunks are not kept).
constexpr std::uint64_t kLookaheadBytes = 256ull << 20;
constexpr std::size_t kHistory = 4096;  // odometry samples kept for late scans
constexpr std::size_t kTfProbe = 500;   // /tf messages searched for the odom frame
// A scan up to this long before the first odometry sample or after the last one takes that
// sample; further away its odometry is unknown.
constexpr double kOdometryHoldSeconds = 1.0;

// The bytes of a log: a file's size, or the sum of a folder's files (a rosbag2 folder).
std::uint64_t logSize(const std::string& path) {
    std::error_code ec;
    if (!fs::is_directory(path, ec)) {
        const auto n = fs::file_size(path, ec);
        return ec ? 0 : n;
    }
    std::uint64_t n = 0;
    for (const auto& f : fs::directory_iterator(path, ec))
        if (f.is_regular_file(ec)) n += f.file_size(ec);
    return n;
}

std::string listOf(const std::map<std::string, TopicInfo>& topics, const char* type) {
    std::string s;
    for (const auto& [name, info] : topics)
        if (!type || isType(info.type, type)) s += (s.empty() ? "" : ", ") + name;
    return s.empty() ? "none" : s;
}

// The topic a choice names, or the one candidate of `type` (prefer one of `preferred` among
// several). Empty when there is none and `required` is false.
std::string pickTopic(const std::map<std::string, TopicInfo>& topics, const std::string& named,
                      const char* type, std::initializer_list<const char*> preferred,
                      const char* what, const char* flag, std::vector<std::string>& notes,
                      bool required) {
    if (!named.empty()) {
        std::string key = named;
        if (!topics.count(key) && topics.count("/" + key)) key = "/" + key;
        const auto it = topics.find(key);
        if (it == topics.end())
            throw BagError(std::string(flag) + " " + named +
                           ": no such topic (topics: " + listOf(topics, nullptr) + ")");
        if (!isType(it->second.type, type))
            throw BagError(std::string(flag) + " " + named + ": the topic holds " +
                           it->second.type + ", not " + type);
        notes.push_back(std::string(what) + ": " + key + " (" + type + ", " + flag + ")");
        return key;
    }
    std::vector<std::string> found;
    for (const auto& [name, info] : topics)
        if (isType(info.type, type)) found.push_back(name);
    if (found.size() == 1) {
        notes.push_back(std::string(what) + ": " + found[0] + " (the only " + type + " topic)");
        return found[0];
    }
    for (const char* p : preferred)
        for (const auto& f : found)
            if (f == p) {
                notes.push_back(std::string(what) + ": " + f + " (of " +
                                std::to_string(found.size()) + " " + type + " topics; " + flag +
                                " chooses another)");
                return f;
            }
    if (found.size() > 1)
        throw BagError(std::to_string(found.size()) + " " + type + " topics (" +
                       listOf(topics, type) + "): choose one with " + flag);
    if (required)
        throw BagError(std::string("no ") + type + " topic (topics: " + listOf(topics, nullptr) +
                       ")");
    return {};
}

// `m` as a T, or null when it is not one; its bytes checked first (instantiateChecked), a
// corrupt message a BagError naming its topic and time. For the choices made when a bag is
// opened (BagSource::Impl::readOne names the message by its number).
template <class T>
boost::shared_ptr<T> instantiate(const NativeMessage& m) {
    try {
        return instantiateChecked<T>(m);
    } catch (const BagError& e) {
        char buf[64];
        std::snprintf(buf, sizeof(buf), " at t = %.6f s", m.time.toSec());
        throw BagError("the message on " + m.topic() + buf + ": " + e.what());
    }
}

// The first message of `topic` as a T, or null (none, or not a T).
template <class T>
boost::shared_ptr<T> firstMessage(MessageStore& bag, const std::string& topic) {
    auto v = bag.cursor(topic, false);
    NativeMessage m;
    if (v->next(m)) return instantiate<T>(m);
    return nullptr;
}

// The first transform in /tf whose parent is `odom_frame` (its child is the base frame).
std::string baseFrameFromTf(MessageStore& bag, const std::string& tf_topic,
                            const std::string& odom_frame) {
    auto v = bag.cursor(tf_topic, false);
    std::size_t n = 0;
    for (NativeMessage m; v->next(m);) {
        if (++n > kTfProbe) break;
        if (const auto tf = instantiate<tf2_msgs::TFMessage>(m))
            for (const auto& t : tf->transforms)
                if (frameWithoutSlash(t.header.frame_id) == odom_frame)
                    return frameWithoutSlash(t.child_frame_id);
    }
    return {};
}

struct Edge {
    std::string parent;
    Pose2D pose;      // child in the parent's frame
    std::string bad;  // why the transform cannot be used ("" when it can)
};

// Why a /tf_static transform cannot be a mount: not finite, or a rotation of norm 0.
std::string badTransform(const geometry_msgs::Transform& t) {
    const auto& p = t.translation;
    const auto& q = t.rotation;
    char buf[200];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
        std::snprintf(buf, sizeof(buf), "its translation (%g, %g, %g) is not finite", p.x, p.y,
                      p.z);
        return buf;
    }
    if (!std::isfinite(q.x) || !std::isfinite(q.y) || !std::isfinite(q.z) || !std::isfinite(q.w)) {
        std::snprintf(buf, sizeof(buf), "its rotation (quaternion %g, %g, %g, %g) is not finite",
                      q.x, q.y, q.z, q.w);
        return buf;
    }
    if (q.x == 0.0 && q.y == 0.0 && q.z == 0.0 && q.w == 0.0)
        return "its rotation is a quaternion of norm 0";
    return {};
}

void chooseMount(MessageStore& bag, const std::map<std::string, TopicInfo>& topics, BagChoice& c) {
    if (const auto s = firstMessage<sensor_msgs::LaserScan>(bag, c.scan_topic))
        c.laser_frame = frameWithoutSlash(s->header.frame_id);
    std::map<std::string, Edge> edges;  // child -> parent
    for (const char* topic : {"/tf_static", "tf_static"}) {
        const auto it = topics.find(topic);
        if (it == topics.end() || !isType(it->second.type, kTfMessage)) continue;
        auto v = bag.cursor(topic, false);
        for (NativeMessage m; v->next(m);)
            if (const auto tf = instantiate<tf2_msgs::TFMessage>(m))
                for (const auto& t : tf->transforms)
                    edges[frameWithoutSlash(t.child_frame_id)] =
                        Edge{frameWithoutSlash(t.header.frame_id),
                             Pose2D{t.transform.translation.x, t.transform.translation.y,
                                    quaternionYaw(t.transform.rotation)},
                             badTransform(t.transform)};
    }
    Pose2D mount{0.0, 0.0, 0.0};
    std::string f = c.laser_frame, bad;  // bad: the first unusable transform of the chain
    for (std::size_t hops = 0; hops < 64 && f != c.base_frame; ++hops) {
        const auto it = edges.find(f);
        if (it == edges.end()) break;
        if (bad.empty() && !it->second.bad.empty())
            bad = "the transform " + it->second.parent + " -> " + f + ": " + it->second.bad;
        mount = compose(it->second.pose, mount);
        f = it->second.parent;
    }
    c.mount_found = !c.laser_frame.empty() && f == c.base_frame && c.laser_frame != c.base_frame;
    if (c.mount_found && bad.empty() && !finitePose(mount.x, mount.y, mount.phi))
        bad = "the composed pose is not finite";
    if (c.mount_found && !bad.empty())  // an unknown mount would put every point nowhere
        throw BagError("the laser mount of frame '" + c.laser_frame + "' (" + c.base_frame +
                       " -> " + c.laser_frame + " in /tf_static) is not usable: " + bad);
    if (c.mount_found || c.laser_frame == c.base_frame) {
        c.mount_x = mount.x;
        c.mount_y = mount.y;
        c.mount_yaw = mount.phi;
    }
    char buf[256];
    if (c.mount_found)
        std::snprintf(buf, sizeof(buf),
                      "laser mount: %s -> %s from /tf_static: x %.3f m, y %.3f m, yaw %.2f deg",
                      c.base_frame.c_str(), c.laser_frame.c_str(), c.mount_x, c.mount_y,
                      c.mount_yaw * 180.0 / kPi);
    else
        std::snprintf(buf, sizeof(buf), "laser mount: identity (no /tf_static chain %s -> %s)",
                      c.base_frame.c_str(), c.laser_frame.empty() ? "?" : c.laser_frame.c_str());
    c.notes.push_back(buf);
}

// The scan topics kfd does not read (MultiEchoLaserScan), each said in the notes; when the bag
// has no LaserScan to read, the error says what it holds instead.
void chooseScans(const std::map<std::string, TopicInfo>& topics, const SourceOptions& o,
                 BagChoice& c) {
    for (const auto& [name, info] : topics)
        if (isType(info.type, kMultiEcho))
            c.unread_scans.push_back(name + " (" + kMultiEcho + ", " +
                                     plural(info.count, "message") + ")");
    try {
        c.scan_topic = pickTopic(topics, o.scan_topic, kLaserScan, {"/scan", "scan"}, "scans",
                                 "--scan-topic", c.notes, true);
    } catch (const BagError& e) {
        if (c.unread_scans.empty()) throw;
        throw BagError(std::string(e.what()) + "; kfd reads " + kLaserScan + " only, not " +
                       c.unread_scans.front() + " (convert one echo to a LaserScan topic first)");
    }
    for (const std::string& t : c.unread_scans)
        c.notes.push_back("not read: " + t + ": kfd reads " + kLaserScan +
                          " only; a bag output copies it unfiltered");
}

BagChoice choose(MessageStore& bag, const std::map<std::string, TopicInfo>& topics,
                 const SourceOptions& o) {
    BagChoice c;
    chooseScans(topics, o, c);
    c.odom_frame = o.odom_frame.empty() ? "odom" : frameWithoutSlash(o.odom_frame);
    std::string tf_topic;
    for (const char* t : {"/tf", "tf"})
        if (topics.count(t) && isType(topics.at(t).type, kTfMessage)) tf_topic = t;
    const std::string mode = o.odom_topic;
    std::string tf_child;  // the child of the odom frame in /tf, once looked up
    if (mode == "none") {
        c.notes.push_back("odometry: none (--odom-topic none): laser only");
    } else if (mode == "tf") {
        if (tf_topic.empty()) throw BagError("--odom-topic tf: the bag has no /tf topic");
        c.odometry = BagChoice::Odometry::Tf;
    } else {
        c.odom_topic = pickTopic(topics, mode, kOdometry, {"/odom", "odom"}, "odometry",
                                 "--odom-topic", c.notes, false);
        if (c.odom_topic.empty() && !tf_topic.empty())
            tf_child = baseFrameFromTf(bag, tf_topic, c.odom_frame);
        if (!c.odom_topic.empty()) {
            c.odometry = BagChoice::Odometry::Topic;
        } else if (!tf_child.empty()) {
            c.odometry = BagChoice::Odometry::Tf;
        } else {
            c.notes.push_back("odometry: none (no " + std::string(kOdometry) + " topic, no " +
                              c.odom_frame + " frame in /tf): laser only");
        }
    }
    if (c.odometry == BagChoice::Odometry::Topic) {
        c.base_frame = frameWithoutSlash(o.base_frame);
        if (c.base_frame.empty())
            if (const auto od = firstMessage<nav_msgs::Odometry>(bag, c.odom_topic))
                c.base_frame = frameWithoutSlash(od->child_frame_id);
    } else if (c.odometry == BagChoice::Odometry::Tf) {
        c.odom_topic = tf_topic;
        c.base_frame = frameWithoutSlash(o.base_frame);
        if (c.base_frame.empty())
            c.base_frame =
                !tf_child.empty() ? tf_child : baseFrameFromTf(bag, tf_topic, c.odom_frame);
        if (c.base_frame.empty())
            throw BagError("--odom-topic tf: no transform from the " + c.odom_frame +
                           " frame in the first " + std::to_string(kTfProbe) +
                           " /tf messages (--odom-frame names it)");
        c.notes.push_back("odometry: " + tf_topic + " " + c.odom_frame + " -> " + c.base_frame +
                          (mode == "tf" ? " (--odom-topic tf)" : " (no Odometry topic)"));
    }
    if (c.base_frame.empty()) c.base_frame = "base_link";
    chooseMount(bag, topics, c);
    return c;
}

}  // namespace

struct BagSource::Impl {
    struct Item {
        std::shared_ptr<const NativeMessage> native;
        CObservation2DRangeScan::Ptr scan;  // null for other messages
        double stamp = 0.0;                 // the scan's header stamp
        double record = 0.0;                // bag time
        bool resolved = true;
        bool odom_emitted = false;
        std::optional<Pose2D> odom;
    };
    struct Sample {
        double t;
        Pose2D p;
    };

    std::string path;
    // Chunks are checked as they are loaded: each is decompressed once, when it is read.
    std::unique_ptr<MessageStore> store;
    std::map<std::string, TopicInfo> topics;
    BagChoice choice;
    std::string label;  // the scans' sensor label: the scan topic without its leading '/'
    std::unique_ptr<MessageStore::Cursor> cursor;
    bool at_end = false;
    std::uint64_t size = 0;
    std::size_t total_messages = 0, messages_read = 0, entries = 0;
    std::deque<Item> queue;
    std::uint64_t queued_bytes = 0;  // the messages' bytes in the queue
    std::deque<Sample> history;
    double last_record = 0.0;
    OdometryTracker tracker;
    SourceCounters counts;

    Impl(const std::string& p, const SourceOptions& o)
        : path(p), store(openMessageStore(p, false)) {
        try {
            topics = store->topics();
            choice = choose(*store, topics, o);
            label = frameWithoutSlash(choice.scan_topic);
            cursor = store->cursor({}, true);
            total_messages = cursor->size();
        } catch (const BagFileError&) {
            throw;
        } catch (const BagError& e) {
            throw BagError(path + ": " + e.what(), path);
        } catch (const std::exception& e) {
            throw BagError(
                path + ": cannot read the bag's index or first messages (" + e.what() + ")", path);
        }
        size = logSize(path);
    }

    std::string where(const NativeMessage& m) const {
        char buf[64];
        std::snprintf(buf, sizeof(buf), " at t = %.6f s", m.time.toSec());
        return path + ": message " + std::to_string(messages_read + 1) + " (" + m.topic() + buf +
               ")";
    }

    static Pose2D interpolate(const Sample& a, const Sample& b, double t) {
        const double w = b.t == a.t ? 0.0 : (t - a.t) / (b.t - a.t);
        return Pose2D{a.p.x + w * (b.p.x - a.p.x), a.p.y + w * (b.p.y - a.p.y),
                      wrapAngle(a.p.phi + w * wrapAngle(b.p.phi - a.p.phi))};
    }

    // Resolves a scan's odometry from the samples seen so far: interpolated between the samples
    // around its stamp; the first sample when the stamp is up to kOdometryHoldSeconds before
    // it, unknown further before it (or before the oldest sample kept). Left unresolved while no
    // sample at or after the stamp has come.
    void resolve(Item& q) const {
        const double t = q.stamp;
        if (history.empty() || history.back().t < t) return;
        std::size_t k = history.size() - 1;  // the first sample at or after t, from the back
        while (k > 0 && history[k - 1].t >= t) --k;
        q.resolved = true;
        if (history[k].t == t)
            q.odom = history[k].p;
        else if (k > 0)
            q.odom = interpolate(history[k - 1], history[k], t);
        else if (history[0].t - t <= kOdometryHoldSeconds)
            q.odom = history[0].p;
    }

    void onSample(double t, const Pose2D& p) {
        if (!finitePose(p.x, p.y, p.phi) || !std::isfinite(t)) return;
        history.push_back(Sample{t, p});
        if (history.size() > kHistory) history.pop_front();
        for (Item& q : queue)
            if (!q.resolved) resolve(q);
    }

    // A scan whose next odometry sample never comes (the bag ends, or the lookahead runs out):
    // the last sample when it is at most kOdometryHoldSeconds older, else unknown.
    void hold(Item& q) {
        if (!history.empty() && q.stamp - history.back().t <= kOdometryHoldSeconds)
            q.odom = history.back().p;
        q.resolved = true;
    }

    // A message's stamp: its header's, or its bag time when the header's is 0 (unset; counted).
    double stampOf(const std_msgs::Header& h, double record) {
        if (!h.stamp.isZero()) return h.stamp.toSec();
        ++counts.stamps_zero;
        return record;
    }

    // The MRPT scan of a LaserScan stamped `stamp` (kfd/io/laser_scan.h, the node's too);
    // angle fields that do not match the beam count are counted.
    CObservation2DRangeScan::Ptr toScan(const sensor_msgs::LaserScan& m, double stamp) {
        counts.scans_bad_angles += laserAnglesMatch(m) ? 0 : 1;
        return laserScanToObservation(m, stamp, label,
                                      Pose2D{choice.mount_x, choice.mount_y, choice.mount_yaw});
    }

    // The bag's next message; null at its end.
    std::shared_ptr<NativeMessage> nextMessage() {
        auto native = std::make_shared<NativeMessage>();
        // A chunk that cannot be read: BagError "PATH: byte N: ..." (the chunk's record).
        try {
            if (!cursor->next(*native)) return nullptr;
        } catch (const BagFileError&) {
            throw;
        } catch (const std::exception& e) {
            throw BagError(path + ": message " + std::to_string(messages_read + 1) +
                               ": corrupt or truncated bag (" + e.what() + ")",
                           path);
        }
        return native;
    }

    // Reads one message into the queue; false at the end of the bag.
    bool readOne() {
        if (at_end) return false;
        const std::shared_ptr<NativeMessage> native = nextMessage();
        if (!native) {
            at_end = true;
            return false;
        }
        const NativeMessage& m = *native;
        try {
            Item item;
            item.native = native;
            item.record = m.time.toSec();
            const std::string& topic = m.topic();
            if (topic == choice.scan_topic) {
                const auto ls = instantiateChecked<sensor_msgs::LaserScan>(m);
                if (!ls) throw BagError("not a " + std::string(kLaserScan));
                item.stamp = stampOf(ls->header, item.record);
                item.scan = toScan(*ls, item.stamp);
                if (choice.odometry != BagChoice::Odometry::None) {
                    item.resolved = false;
                    resolve(item);
                }
            } else if (choice.odometry == BagChoice::Odometry::Topic &&
                       topic == choice.odom_topic) {
                if (const auto od = instantiateChecked<nav_msgs::Odometry>(m))
                    onSample(stampOf(od->header, item.record),
                             Pose2D{od->pose.pose.position.x, od->pose.pose.position.y,
                                    quaternionYaw(od->pose.pose.orientation)});
            } else if (choice.odometry == BagChoice::Odometry::Tf && topic == choice.odom_topic) {
                if (const auto tf = instantiateChecked<tf2_msgs::TFMessage>(m))
                    for (const auto& t : tf->transforms)
                        if (frameWithoutSlash(t.header.frame_id) == choice.odom_frame &&
                            frameWithoutSlash(t.child_frame_id) == choice.base_frame)
                            onSample(stampOf(t.header, item.record),
                                     Pose2D{t.transform.translation.x, t.transform.translation.y,
                                            quaternionYaw(t.transform.rotation)});
            }
            queued_bytes += native->bytes.size();
            queue.push_back(std::move(item));
            last_record = std::max(last_record, queue.back().record);
            ++messages_read;
        } catch (const BagError& e) {
            throw BagError(where(m) + ": " + e.what(), path);
        } catch (const std::exception& e) {
            throw BagError(where(m) + ": corrupt or truncated bag (" + e.what() + ")", path);
        }
        // Bounded lookahead: a scan waits at most kLookaheadSeconds of bag time.
        while (!queue.empty() && !queue.front().resolved &&
               (last_record - queue.front().record > kLookaheadSeconds ||
                queue.size() > kLookaheadMessages || queued_bytes > kLookaheadBytes))
            hold(queue.front());
        return true;
    }
};

BagSource::BagSource(const std::string& path, const SourceOptions& options)
    : impl_(std::make_unique<Impl>(path, options)) {}
BagSource::~BagSource() = default;

bool BagSource::next(SourceEntry& e) {
    Impl& d = *impl_;
    while (d.queue.empty() || !d.queue.front().resolved) {
        if (!d.readOne()) {
            for (auto& q : d.queue)
                if (!q.resolved) d.hold(q);
            if (d.queue.empty()) {
                if (d.entries == 0) throw BagError(d.path + ": the bag holds no messages", d.path);
                return false;
            }
        }
    }
    Impl::Item& q = d.queue.front();
    e = SourceEntry();
    e.index = d.entries++;
    e.objects_read = d.messages_read;
    if (q.scan && q.odom && !q.odom_emitted) {  // the scan's odometry first
        auto odo = std::make_shared<CObservationOdometry>();
        odo->sensorLabel = "ODOMETRY";
        odo->timestamp = q.scan->timestamp;
        odo->odometry = mrpt::poses::CPose2D(q.odom->x, q.odom->y, q.odom->phi);
        d.tracker.onObservation(*odo);
        e.kind = SourceEntry::Kind::Observation;
        e.observation = std::move(odo);
        e.odometry = d.tracker.current();
        q.odom_emitted = true;
        return true;
    }
    if (q.scan) {
        e.kind = SourceEntry::Kind::Observation;
        e.observation = q.scan;
        e.odometry = q.odom;
        if (d.choice.odometry != BagChoice::Odometry::None && !q.odom)
            ++d.counts.scans_without_odometry;
    } else {
        e.kind = SourceEntry::Kind::Native;
        e.odometry = d.tracker.current();
    }
    e.native = std::move(q.native);
    d.queued_bytes -= e.native ? e.native->bytes.size() : 0;
    d.queue.pop_front();
    return true;
}

const std::string& BagSource::path() const { return impl_->path; }
std::uint64_t BagSource::bytesRead() const {
    const Impl& d = *impl_;
    return d.total_messages ? static_cast<std::uint64_t>(static_cast<double>(d.size) *
                                                         static_cast<double>(d.messages_read) /
                                                         static_cast<double>(d.total_messages))
                            : 0;
}
std::uint64_t BagSource::bytesTotal() const { return impl_->size; }
const BagChoice& BagSource::choice() const { return impl_->choice; }
SourceCounters BagSource::counters() const { return impl_->counts; }
std::size_t BagSource::chunks() const { return impl_->store->chunks(); }
std::size_t BagSource::chunksLoaded() const { return impl_->store->chunksLoaded(); }
std::string BagSource::compression() const { return impl_->store->compression(); }
std::string BagSource::kind() const { return impl_->store->kind(); }

SourceListing listBag(const std::string& path, const SourceOptions& options) {
    // The index only: the chunks are read (and checked) as the first messages need them
    // (choose() reads a few), so a compressed bag is listed without decompressing it whole.
    const auto store = openMessageStore(path, false);
    SourceListing l;
    l.path = path;
    l.format = detectFormat(path);
    std::map<std::string, TopicInfo> topics;
    try {
        topics = store->topics();
    } catch (const std::exception& e) {
        throw BagError(path + ": cannot read the bag's index (" + e.what() + ")", path);
    }
    std::size_t total = 0;
    for (const auto& [name, info] : topics) {
        l.streams.push_back({name, info.type, info.count, info.first, info.last});
        total += info.count;
    }
    l.detail =
        store->kind() + ", " + plural(topics.size(), "topic") + ", " + plural(total, "message");
    try {
        const BagChoice c = choose(*store, topics, options);
        l.choices = c.notes;
    } catch (const BagError& e) {
        l.choices.push_back(std::string("cannot use as it is: ") + e.what());
    } catch (const std::exception& e) {
        l.choices.push_back(std::string("cannot read the first messages: ") + e.what());
    }
    return l;
}

}  // namespace kfd
