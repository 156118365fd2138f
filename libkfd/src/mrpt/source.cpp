#include "kfd/mrpt/source.h"

#include <mrpt/core/Clock.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CObservationOdometry.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>

#include "gz_reader.h"
#include "kfd/mrpt/bag_source.h"
#include "kfd/mrpt/carmen_source.h"
#include "kfd/mrpt/rawlog_source.h"

namespace kfd {
namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
}  // namespace

double stampOf(const mrpt::obs::CObservation& obs) {
    return obs.timestamp == mrpt::Clock::time_point() ? std::numeric_limits<double>::quiet_NaN()
                                                      : mrpt::Clock::toDouble(obs.timestamp);
}

void OdometryTracker::onAction(const mrpt::obs::CActionCollection& actions) {
    if (auto mv = actions.getBestMovementEstimation()) {
        const auto& d = mv->rawOdometryIncrementReading;
        if (!finitePose(d.x(), d.y(), d.phi())) {  // this reading only is bad (kfd::checkScan)
            current_ = Pose2D{kNaN, kNaN, kNaN};
            return;
        }
        accum_ = accum_ + d;
        current_ = Pose2D{accum_.x(), accum_.y(), accum_.phi()};
    }
}

void OdometryTracker::onObservation(const mrpt::obs::CObservation& obs) {
    if (const auto* odo = dynamic_cast<const mrpt::obs::CObservationOdometry*>(&obs))
        current_ = Pose2D{odo->odometry.x(), odo->odometry.y(), odo->odometry.phi()};
}

bool finitePose(double x, double y, double phi) {
    return std::isfinite(x) && std::isfinite(y) && std::isfinite(phi);
}

const char* toString(LogFormat f) {
    switch (f) {
        case LogFormat::Rawlog:
            return "MRPT rawlog";
        case LogFormat::Bag:
            return "ROS 1 bag";
        case LogFormat::Carmen:
            return "CARMEN log";
    }
    return "?";
}

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
    if (!std::filesystem::is_regular_file(path, ec))
        throw SourceError("input log not found: " + path, path);
    {
        std::FILE* f = std::fopen(path.c_str(), "rb");
        if (!f) throw SourceError("cannot open the input log " + path, path);
        char head[13] = {};
        const std::size_t n = std::fread(head, 1, sizeof(head), f);
        std::fclose(f);
        if (n >= 9 && std::memcmp(head, "#ROSBAG V", 9) == 0) {
            if (n == 13 && std::memcmp(head, "#ROSBAG V2.0\n", 13) == 0) return LogFormat::Bag;
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
            return std::make_unique<BagSource>(path, options);
        case LogFormat::Carmen:
            return std::make_unique<CarmenSource>(path);
        case LogFormat::Rawlog:
            break;
    }
    return std::make_unique<RawlogSource>(path);
}

namespace {

SourceListing listRawlog(const std::string& path) {
    RawlogSource src(path);
    SourceListing l;
    l.path = path;
    l.format = LogFormat::Rawlog;
    std::map<std::string, SourceListing::Stream> streams;
    std::vector<std::string> order;
    auto note = [&](const mrpt::serialization::CSerializable& o) {
        std::string name = o.GetRuntimeClass()->className;
        for (const char* ns : {"mrpt::obs::", "mrpt::maps::", "mrpt::"})
            if (name.rfind(ns, 0) == 0) {
                name.erase(0, std::strlen(ns));
                break;
            }
        double t = std::numeric_limits<double>::quiet_NaN();
        if (const auto* obs = dynamic_cast<const mrpt::obs::CObservation*>(&o)) {
            name += "[" + obs->sensorLabel + "]";
            t = stampOf(*obs);
        }
        auto [it, fresh] = streams.try_emplace(name);
        if (fresh) {
            order.push_back(name);
            it->second.name = name;
            it->second.type =
                dynamic_cast<const mrpt::obs::CObservation2DRangeScan*>(&o) ? "2D scan" : "";
        }
        ++it->second.count;
        if (std::isfinite(t)) {
            if (it->second.first_stamp == 0.0) it->second.first_stamp = t;
            it->second.last_stamp = t;
        }
    };
    SourceEntry e;
    std::size_t objects = 0;
    while (src.next(e)) {
        objects = e.objects_read;
        e.forEachObject([&](const mrpt::serialization::CSerializable::Ptr& o) {
            if (e.kind == SourceEntry::Kind::Frame && o.get() == e.frame.get()) {
                for (const auto& obs : *e.frame) note(*obs);
            } else if (o) {
                note(*o);
            }
        });
    }
    for (const auto& k : order) l.streams.push_back(streams[k]);
    l.detail = "MRPT rawlog, " + std::to_string(objects) + " objects";
    return l;
}

}  // namespace

SourceListing listSource(const std::string& path, const SourceOptions& options) {
    switch (detectFormat(path)) {
        case LogFormat::Bag:
            return listBag(path, options);
        case LogFormat::Carmen:
            return listCarmen(path);
        case LogFormat::Rawlog:
            break;
    }
    return listRawlog(path);
}

}  // namespace kfd
