// kfd::live::LiveFilter: the live rules of the node (time jumping back, out-of-order scans,
// several lasers, a geometry change, missing odometry) and the marking of removed beams. No ROS
// master: hand-made LaserScan messages straight into the class.
#include "kfd/live/live_filter.h"

#include <gtest/gtest.h>

#include <boost/make_shared.hpp>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "kfd/mrpt/config.h"
#include "kfd/stages/core_stages.h"
#include "ros1/laser_scans.h"

namespace {

using kfd::live::LiveFilter;
using kfd::test::roomScan;

LiveFilter::Params defaults() {
    LiveFilter::Params p;
    p.pipeline = kfd::kfdDefaults();
    return p;
}

TEST(LiveFilter, TimeJumpingBackResetsEveryFrameAndCountsIt) {
    LiveFilter f(defaults());
    for (int i = 0; i < 5; ++i) {
        auto m = roomScan(100.0 + 0.1 * i);
        EXPECT_FALSE(f.process(m, 100.0 + 0.1 * i, std::nullopt, false).reset);
    }
    auto other = roomScan(100.45, "laser2");
    f.process(other, 100.45, std::nullopt, false);
    EXPECT_EQ(f.door().sensorCount(), 2u);
    auto loop = roomScan(10.0);  // the bag started again
    const auto r = f.process(loop, 10.0, std::nullopt, false);
    EXPECT_TRUE(r.reset);
    EXPECT_FALSE(r.out_of_order);
    EXPECT_TRUE(r.publish);  // the first scan of a new stream is a keyframe
    EXPECT_EQ(f.counters().resets, 1u);
    EXPECT_EQ(f.door().sensorCount(), 1u);  // laser2's state went too
    // laser2's next scan, back in the new time line, is a first scan again, not out of order.
    auto other2 = roomScan(10.05, "laser2");
    EXPECT_FALSE(f.process(other2, 10.05, std::nullopt, false).out_of_order);
    EXPECT_EQ(f.counters().out_of_order, 0u);
}

TEST(LiveFilter, SimulatedClockGoingBackResetsHoweverShortTheJump) {
    LiveFilter f(defaults());
    EXPECT_FALSE(f.onClock(20.0));
    auto a = roomScan(20.0), b = roomScan(20.1);
    f.process(a, 20.0, std::nullopt, false);
    EXPECT_FALSE(f.onClock(20.1));
    f.process(b, 20.1, std::nullopt, false);
    EXPECT_TRUE(f.onClock(20.0));  // a 0.1 s bag looping: /clock went back
    EXPECT_EQ(f.counters().resets, 1u);
    EXPECT_EQ(f.door().sensorCount(), 0u);
    auto again = roomScan(20.0);  // its first scan again: not out of order
    EXPECT_FALSE(f.process(again, 20.0, std::nullopt, false).out_of_order);
    EXPECT_FALSE(f.onClock(20.0));  // a clock standing still is no jump
}

TEST(LiveFilter, SlightlyOlderScanIsOutOfOrderAndDropped) {
    LiveFilter f(defaults());
    auto a = roomScan(10.0), b = roomScan(10.2), late = roomScan(10.1);
    f.process(a, 10.0, std::nullopt, false);
    f.process(b, 10.2, std::nullopt, false);
    const std::size_t door_in = f.door().counters().scans_in;
    const auto r = f.process(late, 10.1, std::nullopt, false);
    EXPECT_TRUE(r.out_of_order);
    EXPECT_FALSE(r.publish);
    EXPECT_FALSE(r.reset);
    EXPECT_EQ(f.counters().out_of_order, 1u);
    EXPECT_EQ(f.counters().scans_in, 3u);
    EXPECT_EQ(f.door().counters().scans_in, door_in);  // never reached the door
    // Just under reset_jump older: still out of order; at reset_jump: a reset.
    auto under = roomScan(10.2 - 0.999);
    EXPECT_TRUE(f.process(under, 10.2 - 0.999, std::nullopt, false).out_of_order);
    auto at = roomScan(10.2 - 1.0);
    EXPECT_TRUE(f.process(at, 10.2 - 1.0, std::nullopt, false).reset);
}

TEST(LiveFilter, EqualStampIsNotOutOfOrder) {
    LiveFilter f(defaults());
    auto a = roomScan(5.0), b = roomScan(5.0);
    f.process(a, 5.0, std::nullopt, false);
    EXPECT_FALSE(f.process(b, 5.0, std::nullopt, false).out_of_order);
}

TEST(LiveFilter, EachFrameDecidesAlone) {
    // Two lasers interleaved give each the decisions it gets alone.
    LiveFilter both(defaults()), front_only(defaults()), back_only(defaults());
    for (int i = 0; i < 30; ++i) {
        const double t = 1.0 + 0.1 * i;
        const double shift = 0.05 * i;
        auto f1 = roomScan(t, "front", 181, shift), f2 = f1;
        auto b1 = roomScan(t - 0.5, "back", 361, 0.0), b2 = b1;  // older stamps, other frame
        const auto rf = both.process(f1, t, std::nullopt, false);
        const auto rb = both.process(b1, t - 0.5, std::nullopt, false);
        EXPECT_FALSE(rb.out_of_order) << i;
        EXPECT_EQ(rf.publish, front_only.process(f2, t, std::nullopt, false).publish) << i;
        EXPECT_EQ(rb.publish, back_only.process(b2, t - 0.5, std::nullopt, false).publish) << i;
    }
    EXPECT_EQ(both.door().sensorCount(), 2u);
    EXPECT_EQ(both.counters().scans_kept,
              front_only.counters().scans_kept + back_only.counters().scans_kept);
    EXPECT_EQ(both.counters().geometry_resets, 0u);
}

TEST(LiveFilter, GeometryChangeMidStreamStartsThatFrameAgain) {
    LiveFilter f(defaults());
    for (int i = 0; i < 5; ++i) {
        auto m = roomScan(1.0 + 0.1 * i);
        f.process(m, 1.0 + 0.1 * i, std::nullopt, false);
    }
    auto wider = roomScan(1.5, "laser", 361);  // the driver now sends 361 beams
    const auto r = f.process(wider, 1.5, std::nullopt, false);
    EXPECT_TRUE(r.stream.geometry_reset);
    EXPECT_TRUE(r.publish);
    EXPECT_EQ(wider.ranges.size(), 361u);
    EXPECT_EQ(f.counters().geometry_resets, 1u);
    EXPECT_EQ(f.counters().resets, 0u);
}

TEST(LiveFilter, UnusableGeometryIsCountedNotPublished) {
    LiveFilter f(defaults());
    auto m = roomScan(1.0);
    m.angle_increment = 0.0f;  // angles that do not describe the beams
    const auto r = f.process(m, 1.0, std::nullopt, false);
    EXPECT_FALSE(r.publish);
    EXPECT_NE(r.stream.skipped, kfd::ScanSkipReason::None);
    EXPECT_EQ(f.counters().scans_skipped, 1u);
}

TEST(LiveFilter, MissingOdometryIsCountedOnlyWhenExpected) {
    LiveFilter f(defaults());
    auto a = roomScan(1.0), b = roomScan(1.1), c = roomScan(1.2);
    f.process(a, 1.0, std::nullopt, false);  // ~odom none
    EXPECT_EQ(f.counters().odom_missing, 0u);
    f.process(b, 1.1, std::nullopt, true);  // /tf late or missing
    EXPECT_EQ(f.counters().odom_missing, 1u);
    f.process(c, 1.2, kfd::Pose2D{0.0, 0.0, 0.0}, true);
    EXPECT_EQ(f.counters().odom_missing, 1u);
}

// A room scan with a few stray returns in mid-air: the denoiser removes them.
sensor_msgs::LaserScan noisyScan(double stamp) {
    auto m = roomScan(stamp);
    for (std::size_t i : {30u, 90u, 150u}) m.ranges[i] = 0.7f;
    m.ranges[5] = 40.0f;  // beyond range_max: invalid as received, left as received
    return m;
}

void expectMarked(kfd::RemovedMark mark) {
    auto p = defaults();
    p.removed = mark;
    LiveFilter f(p);
    const auto in = noisyScan(1.0);
    auto out = in;
    const auto r = f.process(out, 1.0, std::nullopt, false);
    ASSERT_TRUE(r.publish);
    ASSERT_GT(r.removed, 0u);
    std::size_t marked = 0;
    for (std::size_t i = 0; i < in.ranges.size(); ++i) {
        if (out.ranges[i] == in.ranges[i]) continue;
        ++marked;
        if (mark == kfd::RemovedMark::NaN)
            EXPECT_TRUE(std::isnan(out.ranges[i])) << i;
        else
            EXPECT_EQ(out.ranges[i], std::numeric_limits<float>::infinity()) << i;
    }
    EXPECT_EQ(marked, r.removed);
    EXPECT_EQ(f.counters().points_removed, r.removed);
    EXPECT_EQ(out.ranges[5], 40.0f);
    EXPECT_EQ(out.header, in.header);
    EXPECT_EQ(out.angle_min, in.angle_min);
    EXPECT_EQ(out.angle_increment, in.angle_increment);
    EXPECT_EQ(out.intensities, in.intensities);
}

TEST(LiveFilter, RemovedBeamsAreNaN) { expectMarked(kfd::RemovedMark::NaN); }
TEST(LiveFilter, RemovedBeamsArePlusInfWhenAsked) { expectMarked(kfd::RemovedMark::PlusInf); }

}  // namespace

namespace {

// next_scan (issue 25): each keyframe waits for its frame's next scan, then comes out of
// takeReady() marked, in order, before the call's own publish.
LiveFilter::Params nextScan() {
    LiveFilter::Params p = defaults();
    p.pipeline.get<kfd::EvidenceDenoiseStage>().next_scan = true;
    return p;
}

// The stamps a node would publish, in order, for scans of a robot moving along +x (`frames`
// lasers interleaved), with the node's calls: process, takeReady, the call's own publish;
// finish() at the end.
std::vector<std::pair<std::string, double>> published(LiveFilter& f, int n, int frames = 1) {
    std::vector<std::pair<std::string, double>> out;
    const auto take = [&] {
        for (sensor_msgs::LaserScan::Ptr m; f.takeReady(m);)
            out.emplace_back(m->header.frame_id, m->header.stamp.toSec());
    };
    for (int i = 0; i < n; ++i)
        for (int k = 0; k < frames; ++k) {
            const double t = 1.0 + 0.1 * i + 0.01 * k;
            auto m = roomScan(t, "laser" + std::to_string(k), 181, 0.04 * i);
            const auto r = f.process(m, t, std::nullopt, false);
            take();
            if (r.publish) out.emplace_back(m.header.frame_id, m.header.stamp.toSec());
        }
    f.finish();
    take();
    return out;
}

TEST(LiveFilter, NextScanHoldsAKeyframeUntilTheFramesNextScan) {
    LiveFilter f(nextScan());
    auto a = roomScan(1.0);
    const auto r = f.process(a, 1.0, std::nullopt, false);
    EXPECT_TRUE(r.pending);
    EXPECT_FALSE(r.publish);
    EXPECT_EQ(f.heldCount(), 1u);
    EXPECT_EQ(f.counters().scans_kept, 0u);  // counted once published
    sensor_msgs::LaserScan::Ptr m;
    EXPECT_FALSE(f.takeReady(m));
    auto b = roomScan(1.1);
    f.process(b, 1.1, std::nullopt, false);
    ASSERT_TRUE(f.takeReady(m));
    EXPECT_DOUBLE_EQ(m->header.stamp.toSec(), 1.0);
    EXPECT_EQ(m->ranges.size(), a.ranges.size());
    EXPECT_EQ(f.counters().scans_kept, 1u);
    EXPECT_FALSE(f.takeReady(m));
}

TEST(LiveFilter, NextScanPublishesTheSameScansInTheSameOrder) {
    for (int frames : {1, 2}) {
        LiveFilter off(defaults()), on(nextScan());
        const auto a = published(off, 40, frames), b = published(on, 40, frames);
        EXPECT_GT(a.size(), 2u);
        EXPECT_LT(a.size(), 40u * frames);  // some dropped: the order is not trivial
        EXPECT_EQ(a, b) << frames << " frame(s)";
        EXPECT_EQ(on.counters().scans_kept, off.counters().scans_kept);
        EXPECT_EQ(on.heldCount(), 0u);  // the last keyframe was finished, not lost
    }
}

// Three scans of a room with no return where a burst of 12 returns at 0.7 m comes in the fourth
// scan only (nothing before it saw through the burst), then two scans without it: the burst scan as
// published (null if not), how many beams the filter counted removed, and the burst scan's message
// as the caller holds it.
struct BurstRun {
    sensor_msgs::LaserScan::Ptr published;
    std::size_t points_removed = 0;
    sensor_msgs::LaserScan given;
};
BurstRun burstRun(const LiveFilter::Params& p) {
    LiveFilter f(p);
    BurstRun run;
    const auto take = [&] {
        for (sensor_msgs::LaserScan::Ptr m; f.takeReady(m);)
            if (m->header.stamp.toSec() == run.given.header.stamp.toSec()) run.published = m;
    };
    for (int i = 0; i < 5; ++i) {
        const double t = 1.0 + 0.1 * i;
        auto m = roomScan(t, "laser", 181, 0.3 * std::min(i, 3));
        for (std::size_t b = 76; b < 96 && i < 3; ++b) m.ranges[b] = 0.0f;  // no return
        for (std::size_t b = 80; b < 92 && i == 3; ++b) m.ranges[b] = 0.7f;
        const auto r = f.process(m, t, std::nullopt, false);
        if (i == 3) run.given = m;
        take();
        if (r.publish && i == 3) run.published = boost::make_shared<sensor_msgs::LaserScan>(m);
    }
    f.finish();
    take();
    run.points_removed = f.counters().points_removed;
    return run;
}

std::size_t nanIn(const sensor_msgs::LaserScan& m, std::size_t from, std::size_t to) {
    std::size_t n = 0;
    for (std::size_t i = from; i < to; ++i) n += std::isnan(m.ranges[i]) ? 1 : 0;
    return n;
}

// The flat burst is a line, which step 7 (keep_surfaces) keeps whatever the evidence: off here.
LiveFilter::Params withoutSurfaces(LiveFilter::Params p) {
    p.pipeline.get<kfd::EvidenceDenoiseStage>().keep_surfaces = false;
    return p;
}

TEST(LiveFilter, NextScanMarksABurstTheNextScanSeesThrough) {
    const BurstRun on = burstRun(withoutSurfaces(nextScan()));
    ASSERT_TRUE(on.published);
    EXPECT_EQ(nanIn(*on.published, 80, 92), 12u);
    EXPECT_EQ(nanIn(on.given, 0, 181), 0u);  // the caller's message is untouched: a copy
    EXPECT_GE(on.points_removed, 12u);
    const BurstRun off = burstRun(withoutSurfaces(defaults()));
    ASSERT_TRUE(off.published);
    EXPECT_EQ(nanIn(*off.published, 80, 92), 0u);  // without the next scan it stays
}

TEST(LiveFilter, NextScanHeldKeyframeIsPublishedBeforeATimeJumpResets) {
    LiveFilter f(nextScan());
    auto a = roomScan(50.0);
    f.process(a, 50.0, std::nullopt, false);
    ASSERT_EQ(f.heldCount(), 1u);
    auto loop = roomScan(10.0);  // the bag started again
    const auto r = f.process(loop, 10.0, std::nullopt, false);
    EXPECT_TRUE(r.reset);
    EXPECT_TRUE(r.pending);  // the new stream's first keyframe, held in turn
    sensor_msgs::LaserScan::Ptr m;
    ASSERT_TRUE(f.takeReady(m));
    EXPECT_DOUBLE_EQ(m->header.stamp.toSec(), 50.0);
    EXPECT_FALSE(f.takeReady(m));
    EXPECT_FALSE(f.onClock(20.0));
    EXPECT_TRUE(f.onClock(5.0));  // the simulated clock going back
    ASSERT_TRUE(f.takeReady(m));
    EXPECT_DOUBLE_EQ(m->header.stamp.toSec(), 10.0);
    EXPECT_EQ(f.heldCount(), 0u);
    EXPECT_EQ(f.counters().scans_kept, 2u);
}

}  // namespace

// Issue 38: 5 000 distinct frame ids grew kfd_node's memory by ~28 KB each, forever. The door
// keeps at most 64 frames' state; the counter says how many were dropped.
TEST(LiveFilter, AFloodOfFrameIdsKeepsBoundedStateAndCountsIt) {
    LiveFilter f(defaults());
    for (int i = 0; i < 1000; ++i) {
        auto m = roomScan(1.0 + 0.01 * i, "frame" + std::to_string(i));
        f.process(m, 1.0 + 0.01 * i, std::nullopt, false);
    }
    EXPECT_LE(f.door().sensorCount(), kfd::StreamFilter::kDefaultMaxSensors);
    EXPECT_EQ(f.counters().sensors_evicted, 1000u - kfd::StreamFilter::kDefaultMaxSensors);
    EXPECT_EQ(f.counters().scans_kept, 1000u);
    bool listed = false;
    for (const auto& [key, value] : kfd::live::counterValues(f.counters()))
        listed = listed || (key == "sensors_evicted" && value == 936.0);
    EXPECT_TRUE(listed);
}

// ~max_sensors: the bound is the user's (a robot with many lasers raises it, a small one lowers
// it); the frame heard from longest ago goes first.
TEST(LiveFilter, TheFrameBoundIsAParameter) {
    LiveFilter::Params p = defaults();
    p.max_sensors = 2;
    LiveFilter f(p);
    for (const char* frame : {"a", "b", "a", "c", "a"}) {
        auto m = roomScan(f.counters().scans_in + 1.0, frame);
        f.process(m, f.counters().scans_in + 1.0, std::nullopt, false);
    }
    EXPECT_EQ(f.door().sensorCount(), 2u);
    EXPECT_EQ(f.counters().sensors_evicted, 1u);  // b, when c came; a was heard since
}
