// What a log holds, for `--list`: listSource() tells the format (detectFormat) and lists the
// log with its format's lister (a rawlog's here, listBag in kfd/io/bag_source.h, listCarmen
// in kfd/io/carmen_source.h).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "kfd/io/source.h"

namespace kfd {

/// What a log holds, for `--list`: its streams (a bag's topics, a CARMEN log's line kinds, a
/// rawlog's object classes and sensor labels) and, for a bag, what a source would use.
struct SourceListing {
    struct Stream {
        std::string name;  // topic, line keyword, or "Class[label]"
        std::string type;  // message type, or what kfd makes of it
        std::size_t count = 0;
        double first_stamp = 0.0, last_stamp = 0.0;  // seconds; 0 when unknown
    };
    std::string path;
    LogFormat format = LogFormat::Rawlog;
    std::string detail;  // e.g. "ROS 1 bag, 4 topics, 22125 messages"
    std::vector<Stream> streams;
    std::vector<std::string> choices;  // "scans: /scan (the only sensor_msgs/LaserScan
                                       // topic)", ...; a CARMEN log's PARAMs
};

/// Reads the log at `path` once (a bag only through its index) and lists it. Throws
/// SourceError like openSource (and for a bag, the errors of BagSource's topic choice are
/// reported as choices, not thrown).
SourceListing listSource(const std::string& path, const SourceOptions& options = {});

}  // namespace kfd
