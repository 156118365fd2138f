// The laser_filters-style stages (beam_count, angle_bounds, footprint, intensity) through the door
// on real logs: what each removes is exactly what it should, and nothing else.
#include <cmath>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "kfd/io/open_source.h"
#include "kfd/mrpt/config.h"
#include "kfd/mrpt/scan_adapter.h"
#include "kfd/mrpt/stream_filter.h"

namespace {

std::string dataset(const std::string& rel) { return std::string(KFD_DATASETS_DIR) + "/" + rel; }

// Runs the config on every scan of the log; `check(before, after, result)` sees each scan.
// Returns the number of scans; `totals` gets the run's stage counters.
template <class Check>
std::size_t runLog(const std::string& log, const std::string& yaml, Check check,
                   std::vector<kfd::StageTotal>* totals = nullptr) {
    kfd::StreamFilter filter(kfd::loadYamlText(yaml));
    auto source = kfd::openSource(log);
    kfd::SourceEntry e;
    std::size_t scans = 0;
    while (source->next(e))
        e.forEachScan([&](const mrpt::obs::CObservation2DRangeScan::Ptr& s) {
            kfd::Scan before;
            kfd::toCore(*s, before);
            const auto r = filter.process(*s, e.odometry);
            kfd::Scan after;
            kfd::toCore(*s, after);
            check(before, after, r);
            ++scans;
        });
    if (totals) *totals = filter.counters().stage_totals;
    return scans;
}

TEST(FilterStagesOnRealLogs, AngleBoundsKeepOnlyTheBeamsInsideOnFr079) {
    const std::string log = dataset("fr079/fr079.rawlog");
    if (!std::filesystem::exists(log)) GTEST_SKIP() << "dataset missing: " << log;
    std::size_t removed = 0, outside_left = 0, inside_lost = 0;
    const auto scans = runLog(
        log,
        "pipeline: [angle_bounds]\nangle_bounds:\n  angle_lower_deg: -45\n  angle_upper_deg: 45\n",
        [&](const kfd::Scan& b, const kfd::Scan& a, const kfd::StreamResult& r) {
            EXPECT_TRUE(r.keep);
            removed += r.record.points_in - a.countValid();
            for (std::size_t i = 0; i < a.size(); ++i) {
                const double deg = a.geometry.angle(i) * 180.0 / kfd::kPi;
                const bool in = deg >= -45.0 - 1e-4 && deg <= 45.0 + 1e-4;
                outside_left += !in && a.valid[i];
                inside_lost += in && b.valid[i] && !a.valid[i];
            }
        });
    EXPECT_EQ(scans, 4934u);
    EXPECT_EQ(outside_left, 0u);
    EXPECT_EQ(inside_lost, 0u);
    EXPECT_GT(removed, scans * 100);  // half of a 360-beam half circle, less invalid beams
}

TEST(FilterStagesOnRealLogs, FootprintRemovesReturnsInsideTheBoxOnlyOnMinesUrg) {
    const std::string log = dataset("mines-urg/exp1.rawlog");
    if (!std::filesystem::exists(log)) GTEST_SKIP() << "dataset missing: " << log;
    // A box 0.8 m ahead of the sensor and 0.6 m wide: the near walls of a corridor enter it.
    std::size_t removed = 0, inside_left = 0, outside_lost = 0;
    runLog(log,
           "pipeline: [footprint]\nfootprint:\n  footprint_min_x: 0\n  footprint_max_x: 0.8\n"
           "  footprint_min_y: -0.3\n  footprint_max_y: 0.3\n",
           [&](const kfd::Scan& b, const kfd::Scan& a, const kfd::StreamResult&) {
               const auto& s = a.sensor_pose;
               for (std::size_t i = 0; i < a.size(); ++i) {
                   const double t = a.geometry.angle(i), d = b.range[i];
                   const double lx = d * std::cos(t), ly = d * std::sin(t);
                   const double x = s.x + std::cos(s.phi) * lx - std::sin(s.phi) * ly;
                   const double y = s.y + std::sin(s.phi) * lx + std::cos(s.phi) * ly;
                   const bool in = x >= 0 && x <= 0.8 && y >= -0.3 && y <= 0.3;
                   removed += b.valid[i] && !a.valid[i];
                   inside_left += in && a.valid[i];
                   outside_lost += !in && b.valid[i] && !a.valid[i];
               }
           });
    EXPECT_GT(removed, 0u);
    EXPECT_EQ(inside_left, 0u);
    EXPECT_EQ(outside_lost, 0u);
}

TEST(FilterStagesOnRealLogs, IntensityLeavesALogWithoutIntensitiesAsItIsAndCountsIt) {
    // No log here carries intensities (the URG bag, the RPLIDAR rosbag2 and the Freiburg logs
    // all have none): each scan passes untouched and is counted.
    const std::string log = dataset("ccny-urg/demo.bag");
    if (!std::filesystem::exists(log)) GTEST_SKIP() << "dataset missing: " << log;
    std::size_t changed = 0;
    std::vector<kfd::StageTotal> totals;
    const auto scans = runLog(
        log, "pipeline: [intensity]\nintensity:\n  intensity_lower: 1\n",
        [&](const kfd::Scan& b, const kfd::Scan& a, const kfd::StreamResult&) {
            changed += b.valid != a.valid;
        },
        &totals);
    EXPECT_EQ(scans, 360u);
    EXPECT_EQ(changed, 0u);
    EXPECT_EQ(kfd::totalOf(totals, "scans_without_intensity"), 360.0);
}

// The RPLIDAR rosbag2 with the count varying as an RPLIDAR driver's does (every other scan one
// beam short, every third two beams long): with beam_count every scan leaves with the first
// scan's 360 beams over the same aperture and the chain never restarts; without it, it
// restarts at every change. Each output range is an input beam's or lies between two
// neighbours'.
TEST(FilterStagesOnRealLogs, BeamCountFixesAVaryingCountOnTheRplidarBag) {
    const std::string log = dataset("mumble-rplidar-ros2/no_loop_room");
    if (!std::filesystem::exists(log)) GTEST_SKIP() << "dataset missing: " << log;
    const std::string chain = "distance, view_keyframe, evidence_denoise]\n";
    for (const bool fixed : {true, false}) {
        kfd::StreamFilter filter(
            kfd::loadYamlText(std::string("pipeline: [") + (fixed ? "beam_count, " : "") + chain));
        auto source = kfd::openSource(log);
        kfd::SourceEntry e;
        std::size_t scans = 0, resets = 0, wrong_count = 0, made_up = 0, kept = 0;
        while (source->next(e))
            e.forEachScan([&](const mrpt::obs::CObservation2DRangeScan::Ptr& s) {
                const std::size_t n = s->getScanSize() - (scans % 2) + (scans % 3 == 2 ? 2 : 0);
                s->resizeScan(n);  // MRPT keeps the aperture: the beams spread over it
                kfd::Scan before;
                kfd::toCore(*s, before);
                const auto r = filter.process(*s, e.odometry);
                resets += r.geometry_reset;
                kept += r.keep;
                ++scans;
                if (!fixed) return;
                wrong_count += s->getScanSize() != 360;
                const double scale = double(n - 1) / 359.0;
                for (std::size_t j = 0; j < s->getScanSize(); ++j) {
                    if (!s->getScanRangeValidity(j)) continue;
                    const auto i0 = static_cast<std::size_t>(std::min(j * scale, double(n - 1)));
                    const std::size_t i1 = std::min(i0 + 1, n - 1);
                    const float lo = std::min(before.range[i0], before.range[i1]);
                    const float hi = std::max(before.range[i0], before.range[i1]);
                    made_up += s->getScanRange(j) < lo - 1e-5f || s->getScanRange(j) > hi + 1e-5f;
                }
            });
        EXPECT_EQ(scans, 508u);
        if (fixed) {
            EXPECT_EQ(resets, 0u);
            EXPECT_EQ(wrong_count, 0u);
            EXPECT_EQ(made_up, 0u);
            EXPECT_LT(kept, scans / 2);  // the keyframe selector works on the fixed count
        } else {
            EXPECT_GT(resets, scans / 2);
        }
    }
}

}  // namespace
