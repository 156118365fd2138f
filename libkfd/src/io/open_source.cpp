#include "kfd/io/open_source.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "gz_reader.h"
#include "kfd/io/bag_source.h"
#include "kfd/io/carmen_source.h"
#include "kfd/io/rawlog_source.h"

namespace kfd {
namespace {

bool hasExtension(const std::string& path, const std::string& x) {
    return path.size() > x.size() && path.compare(path.size() - x.size(), x.size(), x) == 0;
}

bool isCarmenKeyword(const std::string& w) {
    static const char* const kKeywords[] = {
        "PARAM",     "SYNC",        "ODOM",        "FLASER",     "RLASER",       "LASER1",
        "LASER2",    "LASER3",      "LASER4",      "RAWLASER1",  "RAWLASER2",    "RAWLASER3",
        "RAWLASER4", "ROBOTLASER1", "ROBOTLASER2", "TRUEPOS",    "NMEAGGA",      "NMEARMC",
        "SONAR",     "BUMPER",      "IMU",         "VECTORMOVE", "ROBOTVELOCITY"};
    for (const char* k : kKeywords)
        if (w == k) return true;
    return false;
}

}  // namespace

LogFormat detectFormat(const std::string& path) {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) {
        if (std::filesystem::is_regular_file(std::filesystem::path(path) / "metadata.yaml", ec))
            return LogFormat::Rosbag2;
        throw SourceError(path + ": a folder without metadata.yaml (not a rosbag2 bag)", path);
    }
    if (!std::filesystem::is_regular_file(path, ec))
        throw SourceError("input log not found: " + path, path);
    {
        std::FILE* f = std::fopen(path.c_str(), "rb");
        if (!f) throw SourceError("cannot open the input log " + path, path);
        char head[16] = {};
        const std::size_t n = std::fread(head, 1, sizeof(head), f);
        std::fclose(f);
        if (n >= 8 && std::memcmp(head, "\x89MCAP0\r\n", 8) == 0) return LogFormat::Mcap;
        if (n == 16 && std::memcmp(head, "SQLite format 3", 16) == 0) return LogFormat::Rosbag2;
        if (n >= 9 && std::memcmp(head, "#ROSBAG V", 9) == 0) {
            if (n >= 13 && std::memcmp(head, "#ROSBAG V2.0\n", 13) == 0) return LogFormat::Bag;
            throw SourceError(path + ": a ROS bag of format " +
                                  std::string(head + 9, head + std::min<std::size_t>(n, 12)) +
                                  " (only 2.0, the format of ROS 1 since 2010, is read)",
                              path);
        }
    }
    // Text? Look at the first 64 KiB (decoded when gzip). A .bag without the bag line is no bag.
    if (hasExtension(path, ".bag"))
        throw SourceError(path + ": not a ROS bag (no '#ROSBAG V2.0' line)", path);
    detail::GzReader in(path);
    std::string text(1 << 16, '\0');
    text.resize(in.isOpen() ? in.Read(text.data(), text.size()) : 0);
    if (text.empty()) return LogFormat::Rawlog;
    std::size_t pos = 0;
    while (pos < text.size()) {
        const std::size_t end = std::min(text.find('\n', pos), text.size());
        const std::string line = text.substr(pos, end - pos);
        pos = end + 1;
        const auto b = line.find_first_not_of(" \t\r");
        if (b == std::string::npos || line[b] == '#') continue;
        const auto e = line.find_first_of(" \t\r", b);
        return isCarmenKeyword(line.substr(b, e == std::string::npos ? e : e - b))
                   ? LogFormat::Carmen
                   : LogFormat::Rawlog;
    }
    // Comments only: the extension decides.
    for (const char* ext : {".clf", ".log", ".clf.gz", ".log.gz"})
        if (hasExtension(path, ext)) return LogFormat::Carmen;
    return LogFormat::Rawlog;
}

std::unique_ptr<Source> openSource(const std::string& path, const SourceOptions& options) {
    return openSource(path, detectFormat(path), options);
}

std::unique_ptr<Source> openSource(const std::string& path, LogFormat format,
                                   const SourceOptions& options) {
    switch (format) {
        case LogFormat::Bag:
        case LogFormat::Rosbag2:
        case LogFormat::Mcap:
            return std::make_unique<BagSource>(path, options);
        case LogFormat::Carmen:
            return std::make_unique<CarmenSource>(path);
        case LogFormat::Rawlog:
            break;
    }
    return std::make_unique<RawlogSource>(path);
}

}  // namespace kfd
