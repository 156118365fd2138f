#include "kfd/sim/denoise_quality.h"

#include <mrpt/obs/CObservation2DRangeScan.h>

#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "kfd/io/open_source.h"
#include "kfd/io/source.h"
#include "kfd/mrpt/stream_filter.h"
#include "kfd/sim/world.h"

namespace kfd {
namespace {

NoiseKind parseKind(const std::string& s) {
    for (auto k : {NoiseKind::Isolated, NoiseKind::Clustered, NoiseKind::Edge})
        if (s == toString(k)) return k;
    throw SimulationError("unknown noise kind '" + s + "' in labels");
}

struct Label {
    std::size_t beam;
    NoiseKind kind;
    NoiseModel model;
};

// scan index -> labelled beams
std::map<std::size_t, std::vector<Label>> readLabels(const std::string& path) {
    std::ifstream f(path);
    if (!f) throw SimulationError("cannot open labels " + path);
    std::map<std::size_t, std::vector<Label>> out;
    std::string line;
    std::getline(f, line);
    const bool with_model = line == "scan,timestamp,beam,kind,model";
    if (line != "scan,timestamp,beam,kind" && !with_model)
        throw SimulationError(path + " is not a kfd-simulate or kfd-inject label file");
    std::size_t lineno = 1;
    while (std::getline(f, line)) {
        ++lineno;
        std::stringstream ss(line);
        std::string scan, stamp, beam, kind, model;
        const bool ok = std::getline(ss, scan, ',') && std::getline(ss, stamp, ',') &&
                        std::getline(ss, beam, ',') &&
                        (with_model ? std::getline(ss, kind, ',') && std::getline(ss, model)
                                    : static_cast<bool>(std::getline(ss, kind)));
        if (!ok) throw SimulationError(path + ":" + std::to_string(lineno) + ": malformed row");
        try {
            const NoiseKind k = parseKind(kind);
            const NoiseModel m = with_model ? parseNoiseModel(model) : NoiseModel::None;
            if (with_model && kindOf(m) != k)
                throw SimulationError("model '" + model + "' is not of kind '" + kind + "'");
            out[std::stoul(scan)].push_back({std::stoul(beam), k, m});
        } catch (const ParameterError&) {  // an unknown model name
            throw SimulationError(path + ":" + std::to_string(lineno) + ": unknown noise model '" +
                                  model + "' in labels");
        } catch (const std::logic_error&) {  // stoul: not a number
            throw SimulationError(path + ":" + std::to_string(lineno) + ": malformed row");
        } catch (const SimulationError& e) {
            throw SimulationError(path + ":" + std::to_string(lineno) + ": " + e.what());
        }
    }
    return out;
}

// A scan's flags before the door and its labels, scored once the door finished it.
struct Scored {
    mrpt::obs::CObservation2DRangeScan::Ptr scan;
    std::vector<std::uint8_t> before;
    std::vector<NoiseKind> kind;
    std::vector<NoiseModel> model;
};

// Adds a kept scan's verdicts to q: every beam valid before the door, clean or noise (by kind,
// model and range band), removed or not.
void tally(const Scored& s, DenoiseQuality& q) {
    const auto& scan = s.scan;
    ++q.scored;
    for (std::size_t i = 0, n = s.before.size(); i < n; ++i) {
        if (!s.before[i]) continue;
        ++q.points;
        const bool removed = !scan->getScanRangeValidity(i);
        const auto ki = static_cast<std::size_t>(s.kind[i]);
        if (s.kind[i] == NoiseKind::Clean) {
            ++q.clean;
            q.removed_clean += removed;
            const double range = scan->getScanRange(i);
            std::size_t band = 0;
            while (band + 1 < q.kBandStartM.size() && range >= q.kBandStartM[band + 1]) ++band;
            ++q.clean_by_band[band];
            q.removed_clean_by_band[band] += removed;
        } else {
            ++q.noise;
            ++q.noise_by_kind[ki];
            q.removed_noise += removed;
            q.removed_by_kind[ki] += removed;
            const auto mi = static_cast<std::size_t>(s.model[i]);
            ++q.noise_by_model[mi];
            q.removed_by_model[mi] += removed;
        }
    }
}

}  // namespace

DenoiseQuality evaluateDenoising(const std::string& rawlog, const std::string& labels_csv,
                                 const Pipeline::Params& pipeline, bool laser_only) {
    const auto labels = readLabels(labels_csv);
    const auto source = openSource(rawlog);
    StreamFilter filter(pipeline, {}, true);  // the door holds a scan for its next (next_scan)
    filter.setLaserOnly(laser_only);
    DenoiseQuality q;
    SourceEntry e;
    auto score = [&](const mrpt::obs::CObservation2DRangeScan::Ptr& scan) {
        const std::size_t n = scan->getScanSize();
        auto now = std::make_shared<Scored>();
        now->scan = scan;
        now->before.resize(n);
        now->kind.assign(n, NoiseKind::Clean);
        now->model.assign(n, NoiseModel::None);
        for (std::size_t i = 0; i < n; ++i) now->before[i] = scan->getScanRangeValidity(i);
        if (const auto it = labels.find(q.scans); it != labels.end())
            for (const auto& l : it->second) {
                if (l.beam >= n) throw SimulationError("labels do not fit the rawlog");
                now->kind[l.beam] = l.kind;
                now->model[l.beam] = l.model;
            }
        ++q.scans;
        filter.process(*scan, e.odometry, [&, now](StreamResult& f) {
            q.microseconds += f.report.microseconds;  // its whole time, held part included
            if (f.keep) tally(*now, q);  // dropped: the SLAM never sees it, nothing to score
        });
    };
    while (source->next(e)) e.forEachScan(score);
    filter.finish();  // the last keyframe, when held for its next scan
    if (q.scans == 0) throw SimulationError("no scans in " + rawlog);
    if (!labels.empty() && labels.rbegin()->first >= q.scans)
        throw SimulationError("labels refer to more scans than the rawlog holds");
    return q;
}

}  // namespace kfd
