// The input flags of the apps that read logs (kfd-filter, kfd-icp-slam, kfd-render): a bag's
// topics and frames, and --list. Header-only: only those apps link kfd's MRPT layer.
#pragma once

#include <cstdio>
#include <string>

#include "common/cli.h"
#include "kfd/io/source.h"
#include "kfd/io/source_listing.h"

namespace kfd::app {

/// `laser_only`: --laser-only, "ignore the log's odometry" (`laser_only_help` says what else).
inline void addSourceOptions(Cli& cli, kfd::SourceOptions& o, bool& list, bool& laser_only,
                             const char* laser_only_help) {
    cli.flag("--laser-only", laser_only,
             std::string("ignore the log's odometry: kfd decides from the scans\nalone") +
                 laser_only_help);
    cli.option("--scan-topic", o.scan_topic,
               "bag: the sensor_msgs/LaserScan topic\n"
               "(default: the only one, else /scan)")
        ->type_name("TOPIC");
    cli.option("--odom-topic", o.odom_topic,
               "bag: a nav_msgs/Odometry topic, 'tf' (odom -> base\n"
               "from /tf) or 'none' (laser only); default: the only\n"
               "Odometry topic (else /odom), else /tf, else none")
        ->type_name("TOPIC");
    cli.option("--odom-frame", o.odom_frame, "bag, odometry from /tf: the odometry frame (odom)")
        ->type_name("FRAME");
    cli.option("--base-frame", o.base_frame,
               "bag: the robot frame (default: the Odometry's\n"
               "child_frame_id, else odom's child in /tf, else base_link)")
        ->type_name("FRAME");
    cli.flag("--list", list,
             "print what the input holds (a bag's topics, a CARMEN\n"
             "log's lines, a rawlog's objects) and what kfd reads\n"
             "from it, then exit");
}

/// Prints `kfd::listSource(path, o)` on stdout.
inline void printListing(const std::string& path, const kfd::SourceOptions& o) {
    const kfd::SourceListing l = kfd::listSource(path, o);
    std::printf("%s: %s\n", l.path.c_str(), l.detail.c_str());
    std::size_t w = 4;
    for (const auto& s : l.streams) w = std::max(w, s.name.size());
    for (const auto& s : l.streams) {
        std::printf("  %-*s %-24s %8zu", static_cast<int>(w), s.name.c_str(), s.type.c_str(),
                    s.count);
        if (s.last_stamp > 0.0) {
            const double span = s.last_stamp - s.first_stamp;
            std::printf("  %.3f .. %.3f s (%.1f s", s.first_stamp, s.last_stamp, span);
            if (span > 0.0 && s.count > 1)  // messages per second over the span
                std::printf(", %.1f Hz", static_cast<double>(s.count - 1) / span);
            std::printf(")");
        }
        std::printf("\n");
    }
    for (const auto& c : l.choices) std::printf("  %s\n", c.c_str());
}

}  // namespace kfd::app
