#include "kfd/io/source_listing.h"

#include <mrpt/obs/CObservation.h>
#include <mrpt/obs/CObservation2DRangeScan.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <map>

#include "kfd/io/bag_source.h"
#include "kfd/io/carmen_source.h"
#include "kfd/io/open_source.h"
#include "kfd/io/rawlog_source.h"
#include "kfd/pipeline/format.h"

namespace kfd {
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
    l.detail = "MRPT rawlog, " + plural(objects, "object");
    return l;
}

}  // namespace

SourceListing listSource(const std::string& path, const SourceOptions& options) {
    switch (detectFormat(path)) {
        case LogFormat::Bag:
        case LogFormat::Rosbag2:
        case LogFormat::Mcap:
            return listBag(path, options);
        case LogFormat::Carmen:
            return listCarmen(path);
        case LogFormat::Rawlog:
            break;
    }
    return listRawlog(path);
}

}  // namespace kfd
