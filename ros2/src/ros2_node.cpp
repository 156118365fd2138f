#include "kfd/ros2/ros2_node.h"

#include <chrono>
#include <cmath>
#include <cstdio>

#include "kfd/algorithms/pose.h"
#include "kfd/algorithms/scan_tracker.h"
#include "kfd/io/laser_scan.h"
#include "kfd/io/ros2_message.h"
#include "kfd/pipeline/error.h"
#include "kfd/stages/track_stage.h"

namespace kfd::ros2 {

namespace {

diagnostic_msgs::KeyValue kv(const std::string& k, double v) {
    diagnostic_msgs::KeyValue r;
    r.key = k;
    char buf[64];
    std::snprintf(buf, sizeof(buf), "%.10g", v);
    r.value = buf;
    return r;
}

}  // namespace

Ros2Node::Ros2Node(const Ros2Config& config, Ros2Outputs outputs, std::function<double()> now)
    : config_(config),
      out_(std::move(outputs)),
      now_(std::move(now)),
      filter_(live::LiveFilter::Params{config.pipeline, config.removed, config.reset_jump}) {}

void Ros2Node::bad(const std::string& what) {
    if (own_.bad_messages++ == 0 && out_.log)
        out_.log(
            "dropped a message that is not what its topic says (counted as bad_messages; "
            "only the first is logged): " +
            what);
}

template <class Message>
bool Ros2Node::decoded(const std::uint8_t* data, std::size_t size, Message& m) {
    try {
        decodeRos2(data, size, m);
        return true;
    } catch (const Error& e) {
        std::lock_guard<std::mutex> lock(mutex_);
        bad(e.what());
        return false;
    }
}

void Ros2Node::onScan(const std::uint8_t* data, std::size_t size) {
    Waiting w;
    if (!decoded(data, size, w.m)) return;
    w.stamp = w.m.header.stamp.toSec();
    if (w.stamp == 0.0)  // a driver without a clock: the receive time, as the ROS 1 node does
        w.stamp = std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch())
                      .count();
    std::lock_guard<std::mutex> lock(mutex_);
    w.received = now_();
    waiting_.push_back(std::move(w));
    drain(false);
}

void Ros2Node::addOdometry(double stamp, const Pose2D& p) {
    // Time jumped back (a bag looping): the older samples belong to another stream.
    if (odom_.size() > 0 && stamp < odom_.newest() - config_.reset_jump) odom_.clear();
    odom_.add(stamp, p);
    if (odom_down_at_ && odom_.newest() > *odom_down_at_) odom_down_at_.reset();
}

void Ros2Node::onOdometry(const std::uint8_t* data, std::size_t size) {
    nav_msgs::Odometry m;
    if (!decoded(data, size, m)) return;
    std::lock_guard<std::mutex> lock(mutex_);
    if (config_.odometry != Ros2Config::Odometry::Topic) return;
    const auto& p = m.pose.pose;
    addOdometry(m.header.stamp.toSec(),
                Pose2D{p.position.x, p.position.y, quaternionYaw(p.orientation)});
    drain(false);
}

void Ros2Node::onTf(const std::uint8_t* data, std::size_t size, bool is_static) {
    tf2_msgs::TFMessage m;
    if (!decoded(data, size, m)) return;
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& t : m.transforms) {
        const auto& tr = t.transform;
        const Pose2D p{tr.translation.x, tr.translation.y, quaternionYaw(tr.rotation)};
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.phi)) continue;
        const std::string parent = live::frameLabel(t.header.frame_id),
                          child = live::frameLabel(t.child_frame_id);
        if (is_static)
            static_tf_[child] = Edge{parent, p};
        else if (config_.odometry == Ros2Config::Odometry::Tf && parent == config_.odom_frame &&
                 child == config_.base_frame)
            addOdometry(t.header.stamp.toSec(), p);
    }
    if (!is_static) drain(false);
}

Pose2D Ros2Node::mountOf(const std::string& frame) const {
    // The chain base_frame -> ... -> laser in tf_static, as the bag source composes it.
    Pose2D mount{0.0, 0.0, 0.0};
    std::string f = live::frameLabel(frame);
    for (std::size_t hops = 0; hops < 64 && f != config_.base_frame; ++hops) {
        const auto it = static_tf_.find(f);
        if (it == static_tf_.end()) return Pose2D{0.0, 0.0, 0.0};  // identity until it comes
        mount = compose(it->second.pose, mount);
        f = it->second.parent;
    }
    return f == config_.base_frame ? mount : Pose2D{0.0, 0.0, 0.0};
}

bool Ros2Node::odometryCame(double stamp) const {
    return odom_.size() > 0 && odom_.newest() >= stamp;
}

void Ros2Node::tick() {
    std::lock_guard<std::mutex> lock(mutex_);
    drain(false);
}

void Ros2Node::finish() {
    std::lock_guard<std::mutex> lock(mutex_);
    drain(true);
    filter_.finish();  // a keyframe held for its next scan is not lost
    for (sensor_msgs::LaserScan::Ptr done; filter_.takeReady(done);)
        if (out_.scan_filtered) out_.scan_filtered(encodeRos2(*done));
}

void Ros2Node::drain(bool all) {
    const bool odometry = config_.odometry != Ros2Config::Odometry::None;
    while (!waiting_.empty()) {
        Waiting& w = waiting_.front();
        bool go = all || !odometry || odom_down_at_ || odometryCame(w.stamp);
        if (!go && waiting_.size() > static_cast<std::size_t>(config_.queue_size)) {
            ++own_.queue_full;
            go = true;
        }
        if (!go && now_() - w.received >= config_.tf_wait) {
            ++own_.odom_timeouts;
            odom_down_at_ = odom_.size() ? odom_.newest() : -1.0;
            if (out_.log)
                out_.log("no odometry after a scan for " + std::to_string(config_.tf_wait) +
                         " s: laser only until odometry comes again");
            go = true;
        }
        if (!go) return;
        filterOne(w);
        waiting_.pop_front();
    }
}

void Ros2Node::filterOne(Waiting& w) {
    const auto start = std::chrono::steady_clock::now();
    const bool odometry = config_.odometry != Ros2Config::Odometry::None;
    const std::optional<Pose2D> odom = odometry ? odom_.at(w.stamp) : std::nullopt;
    const live::LiveResult r =
        filter_.process(w.m, w.stamp, odom, odometry, mountOf(w.m.header.frame_id));
    if (r.reset) {
        odom_.clear();
        odom_down_at_.reset();
        if (out_.log) out_.log("time jumped back on a scan's frame: state reset");
    }
    for (sensor_msgs::LaserScan::Ptr done; filter_.takeReady(done);)  // held ones first
        if (out_.scan_filtered) out_.scan_filtered(encodeRos2(*done));
    if (r.publish && out_.scan_filtered) out_.scan_filtered(encodeRos2(w.m));
    const TrackResult* t = r.stream.report.find<TrackResult>();
    if (t && out_.track && !config_.track_topic.empty()) {
        nav_msgs::Odometry m;
        m.header.stamp = ros::Time().fromSec(w.stamp);
        m.header.frame_id = config_.odom_frame;
        m.child_frame_id = config_.base_frame;
        m.pose.pose.position.x = t->pose.x;
        m.pose.pose.position.y = t->pose.y;
        m.pose.pose.orientation.z = std::sin(0.5 * t->pose.phi);
        m.pose.pose.orientation.w = std::cos(0.5 * t->pose.phi);
        out_.track(encodeRos2(m));
    }
    work_.add(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start)
                  .count());
}

Bytes Ros2Node::publishDiagnostics(double stamp_s) {
    std::lock_guard<std::mutex> lock(mutex_);
    const live::LiveCounters& c = filter_.counters();
    diagnostic_msgs::DiagnosticStatus s;
    s.name = config_.node_name + ": kfd scan filter";
    s.hardware_id = "kfd";
    const bool worse = own_.bad_messages > reported_.bad_messages ||
                       own_.odom_timeouts > reported_.odom_timeouts ||
                       own_.queue_full > reported_.queue_full;
    reported_ = own_;
    s.level =
        worse ? diagnostic_msgs::DiagnosticStatus::WARN : diagnostic_msgs::DiagnosticStatus::OK;
    char buf[200];
    std::snprintf(buf, sizeof(buf), "%zu of %zu scans kept%s", c.scans_kept, c.scans_in,
                  worse ? "; bad messages or odometry waits since the last report" : "");
    s.message = buf;
    for (const auto& [key, value] : live::counterValues(c)) s.values.push_back(kv(key, value));
    for (const auto& [key, value] :
         {std::pair<const char*, double>{"bad_messages", double(own_.bad_messages)},
          {"odom_timeouts", double(own_.odom_timeouts)},
          {"queue_full", double(own_.queue_full)},
          {"waiting", double(waiting_.size())},
          {"work_p50_us", work_.percentile(50.0)},
          {"work_p99_us", work_.percentile(99.0)},
          {"work_max_us", work_.max()}})
        s.values.push_back(kv(key, value));
    diagnostic_msgs::DiagnosticArray a;
    a.header.stamp = ros::Time().fromSec(stamp_s);
    a.status.push_back(s);
    Bytes b = encodeRos2(a);
    if (out_.diagnostics) out_.diagnostics(b);
    return b;
}

live::LiveCounters Ros2Node::counters() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return filter_.counters();
}

Ros2Counters Ros2Node::ownCounters() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return own_;
}

std::size_t Ros2Node::waiting() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return waiting_.size();
}

double Ros2Node::workPercentile(double p) const {
    std::lock_guard<std::mutex> lock(mutex_);
    return work_.percentile(p);
}

}  // namespace kfd::ros2
