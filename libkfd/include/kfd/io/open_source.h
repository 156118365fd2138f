// Opening a log: its format told by content, and the source for it. The one place that knows
// every Source implementation (rawlog, ROS 1 bag, CARMEN).
#pragma once

#include <memory>
#include <string>

#include "kfd/io/source.h"

namespace kfd {

/// The format of the file at `path`, by content: a ROS bag starts "#ROSBAG V2.0"; a CARMEN log
/// (plain or gzip) is text whose first non-comment line starts with a CARMEN keyword (PARAM,
/// FLASER, ODOM, ...); anything else is read as a rawlog. The extension decides only for a
/// text file of comments alone (.clf/.log: CARMEN). Throws SourceError when the file is
/// missing or unreadable, or is a bag of another version.
LogFormat detectFormat(const std::string& path);

/// Opens the log at `path` with the source for its format (detectFormat): a RawlogSource,
/// BagSource or CarmenSource. Throws SourceError when it cannot be opened, naming the file and
/// the reason.
std::unique_ptr<Source> openSource(const std::string& path, const SourceOptions& options = {});
/// The same with the format already known (from detectFormat), for callers that decide on it
/// before opening (kfd-filter's bag output).
std::unique_ptr<Source> openSource(const std::string& path, LogFormat format,
                                   const SourceOptions& options = {});

}  // namespace kfd
