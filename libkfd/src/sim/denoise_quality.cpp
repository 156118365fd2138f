#include "kfd/sim/denoise_quality.h"

#include <mrpt/obs/CObservation2DRangeScan.h>

#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "kfd/mrpt/source.h"
#include "kfd/mrpt/stream_filter.h"
#include "kfd/sim/world.h"

namespace kfd {
namespace {

NoiseKind parseKind(const std::string& s) {
    for (auto k : {NoiseKind::Isolated, NoiseKind::Clustered, NoiseKind::Edge})
        if (s == toString(k)) return k;
    throw SimulationError("unknown noise kind '" + s + "' in labels");
}

// scan index -> (beam, kind) list
std::map<std::size_t, std::vector<std::pair<std::size_t, NoiseKind>>> readLabels(
    const std::string& path) {
    std::ifstream f(path);
    if (!f) throw SimulationError("cannot open labels " + path);
    std::map<std::size_t, std::vector<std::pair<std::size_t, NoiseKind>>> out;
    std::string line;
    std::getline(f, line);
    if (line != "scan,timestamp,beam,kind")
        throw SimulationError(path + " is not a kfd-simulate label file");
    std::size_t lineno = 1;
    while (std::getline(f, line)) {
        ++lineno;
        std::stringstream ss(line);
        std::string scan, stamp, beam, kind;
        if (!std::getline(ss, scan, ',') || !std::getline(ss, stamp, ',') ||
            !std::getline(ss, beam, ',') || !std::getline(ss, kind))
            throw SimulationError(path + ":" + std::to_string(lineno) + ": malformed row");
        out[std::stoul(scan)].emplace_back(std::stoul(beam), parseKind(kind));
    }
    return out;
}

}  // namespace

DenoiseQuality evaluateDenoising(const std::string& rawlog, const std::string& labels_csv,
                                 const Pipeline::Params& pipeline) {
    const auto labels = readLabels(labels_csv);
    const auto source = openSource(rawlog);
    StreamFilter filter(pipeline);
    DenoiseQuality q;
    std::vector<std::uint8_t> before;
    std::vector<NoiseKind> kind;
    SourceEntry e;
    auto score = [&](const mrpt::obs::CObservation2DRangeScan::Ptr& scan) {
        const std::size_t n = scan->getScanSize();
        before.resize(n);
        kind.assign(n, NoiseKind::Clean);
        for (std::size_t i = 0; i < n; ++i) before[i] = scan->getScanRangeValidity(i);
        if (const auto it = labels.find(q.scans); it != labels.end())
            for (const auto& [beam, k] : it->second) {
                if (beam >= n) throw SimulationError("labels do not fit the rawlog");
                kind[beam] = k;
            }
        const auto r = filter.process(*scan);
        q.microseconds += r.report.microseconds;
        for (std::size_t i = 0; i < n; ++i) {
            if (!before[i]) continue;
            ++q.points;
            const bool removed = r.keep && !scan->getScanRangeValidity(i);
            const auto ki = static_cast<std::size_t>(kind[i]);
            if (kind[i] == NoiseKind::Clean) {
                ++q.clean;
                q.removed_clean += removed;
            } else {
                ++q.noise;
                ++q.noise_by_kind[ki];
                q.removed_noise += removed;
                q.removed_by_kind[ki] += removed;
            }
        }
        ++q.scans;
    };
    while (source->next(e)) e.forEachScan(score);
    if (q.scans == 0) throw SimulationError("no scans in " + rawlog);
    if (!labels.empty() && labels.rbegin()->first >= q.scans)
        throw SimulationError("labels refer to more scans than the rawlog holds");
    return q;
}

}  // namespace kfd
