#include "kfd/ros1/scan_filter_node.h"

#include <diagnostic_msgs/DiagnosticArray.h>
#include <diagnostic_msgs/KeyValue.h>
#include <geometry_msgs/TransformStamped.h>
#include <tf2/exceptions.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <thread>

#include "kfd/algorithms/scan_tracker.h"
#include "kfd/io/laser_scan.h"
#include "kfd/ros1/graceful_stop.h"
#include "kfd/stages/track_stage.h"

namespace kfd::ros1 {

namespace {

Pose2D poseOf(const geometry_msgs::Transform& t) {
    return Pose2D{t.translation.x, t.translation.y, quaternionYaw(t.rotation)};
}

diagnostic_msgs::KeyValue kv(const std::string& k, double v) {
    diagnostic_msgs::KeyValue r;
    r.key = k;
    char buf[64];
    std::snprintf(buf, sizeof(buf), "%.10g", v);
    r.value = buf;
    return r;
}

}  // namespace

std::map<std::string, XmlRpc::XmlRpcValue> ScanFilterNode::privateParams(
    const ros::NodeHandle& pnh) {
    std::map<std::string, XmlRpc::XmlRpcValue> out;
    std::vector<std::string> names;
    ros::param::getParamNames(names);
    const std::string ns = pnh.getNamespace() + "/";
    for (const std::string& name : names) {
        if (name.compare(0, ns.size(), ns) != 0) continue;
        std::string key = name.substr(ns.size());
        key = key.substr(0, key.find('/'));
        if (key.empty() || out.count(key)) continue;
        XmlRpc::XmlRpcValue v;
        if (pnh.getParam(key, v)) out[key] = v;
    }
    return out;
}

ScanFilterNode::ScanFilterNode(ros::NodeHandle nh, ros::NodeHandle pnh)
    : ScanFilterNode(nh, pnh, nodeConfig(privateParams(pnh))) {}

ScanFilterNode::ScanFilterNode(ros::NodeHandle nh, ros::NodeHandle pnh, const NodeConfig& config)
    : config_(config),
      nh_(nh),
      pnh_(pnh),
      filter_(LiveFilter::Params{config.pipeline, config.removed, config.reset_jump,
                                 std::size_t(config.max_sensors)}) {
    for (const std::string& note : config_.notes) ROS_WARN("kfd: %s", note.c_str());
    tf_ = std::make_unique<tf2_ros::Buffer>();
    tf_listener_ = std::make_unique<tf2_ros::TransformListener>(*tf_, nh_, true);
    const auto q = static_cast<std::uint32_t>(config_.queue_size);
    scan_pub_ = nh_.advertise<sensor_msgs::LaserScan>("scan_filtered", q);
    diag_pub_ = nh_.advertise<diagnostic_msgs::DiagnosticArray>("/diagnostics", 1);
    stats_pub_ = pnh_.advertise<diagnostic_msgs::DiagnosticStatus>("stats", 1, true);
    if (!config_.track_topic.empty() && config_.pipeline.lists(TrackStage::kName))
        track_pub_ = nh_.advertise<nav_msgs::Odometry>(config_.track_topic, q);
    if (config_.track_tf) track_tf_ = std::make_unique<tf2_ros::TransformBroadcaster>();
    if (config_.odometry == NodeConfig::Odometry::Topic) {
        ros::SubscribeOptions o = ros::SubscribeOptions::create<nav_msgs::Odometry>(
            "odom", 50, [this](const nav_msgs::Odometry::ConstPtr& m) { onOdometry(m); },
            ros::VoidPtr(), &odom_queue_);
        o.transport_hints = ros::TransportHints().tcpNoDelay();
        odom_sub_ = nh_.subscribe(o);
        odom_spinner_ = std::make_unique<ros::AsyncSpinner>(1, &odom_queue_);
        odom_spinner_->start();
    }
    scan_sub_ =
        nh_.subscribe("scan", q, &ScanFilterNode::onScan, this, ros::TransportHints().tcpNoDelay());
    timer_ = nh_.createWallTimer(ros::WallDuration(1.0),
                                 [this](const ros::WallTimerEvent&) { publishStats(); });
    stop_token_ = GracefulStop::add([this] { stop(); });
}

ScanFilterNode::~ScanFilterNode() {
    timer_.stop();
    if (odom_spinner_) odom_spinner_->stop();
    odom_sub_.shutdown();
    scan_sub_.shutdown();
    // Nodelet unload (ROS goes on, this filter goes): what is held goes out first, then the
    // registration, whose removal passes on a stop asked for meanwhile (GracefulStop).
    if (ros::ok() && finishOnce() > 0) ros::WallDuration(0.3).sleep();  // reaches subscribers
    GracefulStop::remove(stop_token_);
}

void ScanFilterNode::stop() {
    stopping_ = true;  // an onScan waiting for odometry gives up, later scans are dropped
    finishOnce();
}

std::size_t ScanFilterNode::finishOnce() {
    if (finished_.exchange(true)) return 0;  // a stop and an unload may race: one finishes
    const std::size_t held = finish();
    publishStats();
    ROS_INFO("kfd: stopping (%zu held keyframe%s published)", held, held == 1 ? "" : "s");
    return held;
}

std::size_t ScanFilterNode::finish() {
    std::lock_guard<std::mutex> lock(mutex_);
    filter_.finish();  // a keyframe held for its next scan is not lost
    return publishReady();
}

std::size_t ScanFilterNode::publishReady() {
    std::size_t n = 0;
    for (sensor_msgs::LaserScan::Ptr done; filter_.takeReady(done); ++n) scan_pub_.publish(done);
    return n;
}

LiveCounters ScanFilterNode::counters() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return filter_.counters();
}

void ScanFilterNode::onOdometry(const nav_msgs::Odometry::ConstPtr& m) {
    const double t = m->header.stamp.isZero() ? ros::Time::now().toSec() : m->header.stamp.toSec();
    if (!live::usableStamp(t)) return;  // a scan at such a stamp is dropped too
    const Pose2D p{m->pose.pose.position.x, m->pose.pose.position.y,
                   quaternionYaw(m->pose.pose.orientation)};
    {
        std::lock_guard<std::mutex> lock(odom_mutex_);
        // Time jumped back (a bag looping): the older samples belong to another stream.
        if (odom_buffer_.size() > 0 && t < odom_buffer_.newest() - config_.reset_jump)
            odom_buffer_.clear();
        odom_buffer_.add(t, p);
    }
    odom_cv_.notify_all();
}

std::optional<ros::Time> ScanFilterNode::newestTf() const {
    try {
        return tf_->lookupTransform(config_.odom_frame, config_.base_frame, ros::Time(0))
            .header.stamp;
    } catch (const tf2::TransformException&) {
        return std::nullopt;
    }
}

bool ScanFilterNode::newestTfAfter(const ros::Time& stamp) const {
    const std::optional<ros::Time> t = newestTf();
    return t && *t > stamp;
}

double ScanFilterNode::waitBound() const {
    // Before two scans have come, the scan's own scan_time says the pace (a laser-only bag's
    // first scan must not wait ~tf_wait while the queue overflows).
    if (intervals_.empty())
        return scan_time_ > 0.0
                   ? std::min(config_.tf_wait, double(config_.queue_size - 1) * scan_time_)
                   : config_.tf_wait;
    std::array<double, kIntervals> v;  // a copy on the stack: no allocation per scan
    const auto end = std::copy(intervals_.begin(), intervals_.end(), v.begin());
    const auto mid = v.begin() + std::ptrdiff_t(intervals_.size() / 2);
    std::nth_element(v.begin(), mid, end);
    return std::min(config_.tf_wait, double(config_.queue_size - 1) * *mid);
}

template <class Ready>
bool ScanFilterNode::waitFor(const ros::Time& stamp, Ready ready) {
    const double bound = waitBound();
    const ros::Time deadline = stamp + ros::Duration(bound);
    const auto wall_deadline =
        std::chrono::steady_clock::now() + std::chrono::duration<double>(2.0 * bound);
    while (!ready()) {
        if (ros::Time::now() >= deadline || std::chrono::steady_clock::now() >= wall_deadline ||
            !ros::ok() || stopping_)
            return false;
        std::this_thread::sleep_for(std::chrono::microseconds(500));
    }
    return true;
}

// The bag source's rule at the ends of the odometry (kfd-filter -i X.bag): a scan up to
// hold_seconds before the first transform or after the last one takes that transform; further
// away, or in a gap inside the buffer's span, its odometry is unknown.
std::optional<Pose2D> ScanFilterNode::tfAtTheEdges(const ros::Time& stamp) {
    const double hold = odom_buffer_.params().hold_seconds;
    try {
        const auto latest =
            tf_->lookupTransform(config_.odom_frame, config_.base_frame, ros::Time(0));
        if (latest.header.stamp < stamp)
            return stamp.toSec() - latest.header.stamp.toSec() <= hold
                       ? std::optional<Pose2D>(poseOf(latest.transform))
                       : std::nullopt;
        // Before the first transform: tf2 has no query for the oldest one, so the earliest
        // stamp within hold_seconds it can transform at is found by bisection (to 1 us).
        ros::Time lo = stamp, hi = std::min(stamp + ros::Duration(hold), latest.header.stamp);
        if (!tf_->canTransform(config_.odom_frame, config_.base_frame, hi)) return std::nullopt;
        while ((hi - lo).toSec() > 1e-6) {
            const ros::Time mid = lo + ros::Duration((hi - lo).toSec() / 2);
            (tf_->canTransform(config_.odom_frame, config_.base_frame, mid) ? hi : lo) = mid;
        }
        return poseOf(tf_->lookupTransform(config_.odom_frame, config_.base_frame, hi).transform);
    } catch (const tf2::TransformException&) {
        return std::nullopt;
    }
}

std::optional<Pose2D> ScanFilterNode::odometryAt(const ros::Time& stamp) {
    switch (config_.odometry) {
        case NodeConfig::Odometry::None:
            return std::nullopt;
        case NodeConfig::Odometry::Topic: {
            // The sample after the scan usually comes just after it: wait for it at most
            // ~tf_wait, then the bag source's rule on what there is (kfd-filter's lookahead).
            const double t = stamp.toSec();
            waitFor(stamp, [&] {
                std::unique_lock<std::mutex> lock(odom_mutex_);
                return odom_cv_.wait_for(lock, std::chrono::microseconds(500), [&] {
                    return odom_buffer_.size() > 0 && odom_buffer_.newest() >= t;
                });
            });
            std::lock_guard<std::mutex> lock(odom_mutex_);
            return odom_buffer_.at(t);
        }
        case NodeConfig::Odometry::Tf: {
            // Polled every 0.5 ms (tf2's own timed lookup sleeps in steps of 10 ms: too coarse
            // for a laser at 40 Hz). Once a transform newer than the scan is in, waiting cannot
            // help (the scan is before the first one or in a gap): the edge rule decides at
            // once. While /tf is down (the last wait timed out, nothing newer since) scans do
            // not wait, so the scans behind them keep flowing.
            const std::optional<ros::Time> newest = newestTf();
            if (tf_timed_out_at_ && (!newest || *newest <= *tf_timed_out_at_)) {
                if (!tf_->canTransform(config_.odom_frame, config_.base_frame, stamp))
                    return tfAtTheEdges(stamp);
            } else {
                tf_timed_out_at_.reset();
                const bool ready = waitFor(stamp, [&] {
                    return tf_->canTransform(config_.odom_frame, config_.base_frame, stamp) ||
                           newestTfAfter(stamp);
                });
                if (!ready) tf_timed_out_at_ = newestTf().value_or(ros::Time(0));
            }
            try {
                return poseOf(
                    tf_->lookupTransform(config_.odom_frame, config_.base_frame, stamp).transform);
            } catch (const tf2::TransformException&) {
                return tfAtTheEdges(stamp);
            }
        }
    }
    return std::nullopt;
}

Pose2D ScanFilterNode::mountOf(const std::string& frame_id) {
    const std::string laser = frameLabel(frame_id);
    if (const auto it = mounts_.find(laser); it != mounts_.end()) return it->second;
    if (laser.empty() || laser == frameLabel(config_.base_frame)) return Pose2D{0.0, 0.0, 0.0};
    try {
        const auto t = tf_->lookupTransform(config_.base_frame, laser, ros::Time(0));
        const Pose2D p = poseOf(t.transform);
        mounts_[laser] = p;
        return p;
    } catch (const tf2::TransformException&) {
        return Pose2D{0.0, 0.0, 0.0};  // identity until /tf_static has the chain
    }
}

void ScanFilterNode::onScan(const sensor_msgs::LaserScan::ConstPtr& in) {
    // No message may take the node (or the nodelet manager, and a driver loaded there) down:
    // a stamp kfd cannot compute with is dropped and counted before any ros::Time arithmetic,
    // and anything else that throws drops this scan only (issue 38).
    if (stopping_) return;  // stopping: what is held is published, nothing new comes in
    std::lock_guard<std::mutex> lock(mutex_);
    const ros::Time now = ros::Time::now();
    const ros::Time stamp = in->header.stamp.isZero() ? now : in->header.stamp;
    if (!filter_.acceptStamp(stamp.toSec())) {
        ROS_WARN_THROTTLE(5.0,
                          "kfd: scan of frame '%s' stamped %.3f s: a stamp kfd cannot compute "
                          "with (within a day of the end of ROS time): dropped (stamps_unusable)",
                          in->header.frame_id.c_str(), stamp.toSec());
        return;
    }
    try {
        handleScan(in, now, stamp);
    } catch (const std::exception& e) {
        filter_.countError(true);
        ROS_ERROR_THROTTLE(5.0, "kfd: scan of frame '%s' at %.3f s dropped: %s",
                           in->header.frame_id.c_str(), stamp.toSec(), e.what());
    }
}

void ScanFilterNode::handleScan(const sensor_msgs::LaserScan::ConstPtr& in, const ros::Time& now,
                                const ros::Time& stamp) {
    const auto start = std::chrono::steady_clock::now();
    if (last_scan_stamp_ && stamp != *last_scan_stamp_) {  // the queue's pace, every laser
        const double dt = std::abs(stamp.toSec() - last_scan_stamp_->toSec());  // never throws
        if (intervals_.size() < kIntervals)
            intervals_.push_back(dt);
        else
            intervals_[next_interval_++ % intervals_.size()] = dt;
    }
    last_scan_stamp_ = stamp;
    if (std::isfinite(in->scan_time) && in->scan_time > 0.0f && in->scan_time < 10.0f)
        scan_time_ = in->scan_time;
    checkSequence(*in);
    if (ros::Time::isSimTime() && filter_.onClock(now.toSec())) {
        std::lock_guard<std::mutex> odom_lock(odom_mutex_);
        odom_buffer_.clear();
        tf_timed_out_at_.reset();
        ROS_WARN("kfd: the ROS clock jumped back to %.3f s (a bag looping?): state reset",
                 now.toSec());
    }
    const std::optional<Pose2D> odom = odometryAt(stamp);
    const auto ready = std::chrono::steady_clock::now();  // the wait for odometry is over
    const Pose2D mount = mountOf(in->header.frame_id);
    auto out = boost::make_shared<sensor_msgs::LaserScan>(*in);
    const LiveResult r = filter_.process(*out, stamp.toSec(), odom,
                                         config_.odometry != NodeConfig::Odometry::None, mount);
    if (r.reset) {
        std::lock_guard<std::mutex> odom_lock(odom_mutex_);
        odom_buffer_.clear();
        tf_timed_out_at_.reset();
        ROS_WARN("kfd: time jumped back on frame '%s' (scan at %.3f s): state reset",
                 in->header.frame_id.c_str(), stamp.toSec());
    }
    reportScan(*in, stamp, r, odom.has_value());
    publishReady();  // held keyframes (next_scan) finished by a reset or this scan, before it
    if (r.publish) scan_pub_.publish(out);
    publishTrack(r, stamp);
    const auto end = std::chrono::steady_clock::now();
    latency_.add(std::chrono::duration<double, std::micro>(end - start).count());
    work_.add(std::chrono::duration<double, std::micro>(end - ready).count());
}

void ScanFilterNode::checkSequence(const sensor_msgs::LaserScan& m) {
    const std::string frame = frameLabel(m.header.frame_id);
    const auto it = last_seq_.find(frame);
    // A gap of up to 10 000: scans that never arrived; a larger jump or a step back is a
    // publisher that restarted. A driver that leaves seq at 0 never counts.
    if (it != last_seq_.end() && m.header.seq > it->second + 1 &&
        m.header.seq - it->second <= 10000) {
        filter_.countMissing(m.header.seq - it->second - 1);
        if (!warned_missing_)
            ROS_WARN(
                "kfd: %u scan(s) of frame '%s' never arrived (header.seq %u after %u): "
                "lost in the queue (~queue_size) or before kfd; counted in scans_missing",
                m.header.seq - it->second - 1, m.header.frame_id.c_str(), m.header.seq, it->second);
        warned_missing_ = true;
    }
    if (it == last_seq_.end() && last_seq_.size() >= std::size_t(config_.max_sensors))
        last_seq_.clear();  // a flood of frame ids: bounded like the door's sensors
    last_seq_[frame] = m.header.seq;
}

void ScanFilterNode::reportScan(const sensor_msgs::LaserScan& m, const ros::Time& stamp,
                                const LiveResult& r, bool has_odometry) {
    const char* frame = m.header.frame_id.c_str();
    if (config_.odometry != NodeConfig::Odometry::None && !has_odometry && !warned_odom_) {
        warned_odom_ = true;
        const std::string source =
            config_.odometry == NodeConfig::Odometry::Tf
                ? "transform " + config_.odom_frame + " -> " + config_.base_frame
                : "topic " + nh_.resolveName("odom");
        ROS_WARN(
            "kfd: no odometry for the scan of frame '%s' at %.3f s (%s): filtered laser "
            "only, counted in odom_missing; set ~odom: none on a robot without odometry",
            frame, stamp.toSec(), source.c_str());
    }
    if (r.stream.skipped != ScanSkipReason::None)
        ROS_WARN_THROTTLE(5.0, "kfd: scan of frame '%s' at %.3f s has %s: dropped (scans_skipped)",
                          frame, stamp.toSec(), describe(r.stream.skipped));
    if (filter_.counters().sensors_evicted > evicted_seen_) {
        evicted_seen_ = filter_.counters().sensors_evicted;
        ROS_WARN_THROTTLE(5.0,
                          "kfd: more than %d frame ids (~max_sensors): the state of the one heard "
                          "from longest ago was dropped (%zu so far, sensors_evicted)",
                          config_.max_sensors, evicted_seen_);
    }
    if (r.out_of_order)
        ROS_WARN_THROTTLE(5.0, "kfd: scan of frame '%s' at %.3f s is out of order: dropped", frame,
                          stamp.toSec());
}

void ScanFilterNode::publishTrack(const LiveResult& r, const ros::Time& stamp) {
    const TrackResult* t = r.stream.report.find<TrackResult>();
    if (!t || (!track_pub_ && !track_tf_)) return;  // not through the stages, or nothing asked
    geometry_msgs::Quaternion q;
    q.z = std::sin(0.5 * t->pose.phi);
    q.w = std::cos(0.5 * t->pose.phi);
    if (track_pub_) {
        auto m = boost::make_shared<nav_msgs::Odometry>();
        m->header.stamp = stamp;
        m->header.frame_id = config_.odom_frame;
        m->child_frame_id = config_.base_frame;
        m->pose.pose.position.x = t->pose.x;
        m->pose.pose.position.y = t->pose.y;
        m->pose.pose.orientation = q;
        track_pub_.publish(m);
    }
    if (track_tf_) {
        geometry_msgs::TransformStamped tf;
        tf.header.stamp = stamp;
        tf.header.frame_id = config_.odom_frame;
        tf.child_frame_id = config_.base_frame;
        tf.transform.translation.x = t->pose.x;
        tf.transform.translation.y = t->pose.y;
        tf.transform.rotation = q;
        track_tf_->sendTransform(tf);
    }
}

diagnostic_msgs::DiagnosticStatus ScanFilterNode::stats() const {
    std::lock_guard<std::mutex> lock(mutex_);
    const LiveCounters& c = filter_.counters();
    diagnostic_msgs::DiagnosticStatus s;
    s.name = ros::this_node::getName() + ": kfd scan filter";
    s.hardware_id = "kfd";
    char buf[160];
    std::snprintf(buf, sizeof(buf), "%zu of %zu scans kept", c.scans_kept, c.scans_in);
    s.message = buf;
    // Anything lost or degraded raises the level and is named in the message.
    const auto look = live::attention(c, config_.odometry != NodeConfig::Odometry::None);
    s.level = look.empty() ? diagnostic_msgs::DiagnosticStatus::OK
                           : diagnostic_msgs::DiagnosticStatus::WARN;
    for (const std::string& what : look) s.message += "; " + what;
    for (const auto& [key, value] : live::counterValues(c)) s.values.push_back(kv(key, value));
    for (const auto& [key, value] :
         {std::pair<const char*, double>{"latency_p50_us", latency_.percentile(50.0)},
          {"latency_p99_us", latency_.percentile(99.0)},
          {"latency_max_us", latency_.max()},
          {"work_p50_us", work_.percentile(50.0)},
          {"work_p99_us", work_.percentile(99.0)},
          {"work_max_us", work_.max()}})
        s.values.push_back(kv(key, value));
    return s;
}

void ScanFilterNode::publishStats() {
    const auto s = stats();
    stats_pub_.publish(s);
    diagnostic_msgs::DiagnosticArray a;
    a.header.stamp = ros::Time::now();
    a.status.push_back(s);
    diag_pub_.publish(a);
}

}  // namespace kfd::ros1
