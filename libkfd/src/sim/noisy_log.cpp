#include "kfd/sim/noisy_log.h"

#include <mrpt/obs/CObservation2DRangeScan.h>

#include <algorithm>
#include <filesystem>
#include <random>
#include <vector>

#include "kfd/io/gz_output.h"
#include "kfd/io/open_source.h"
#include "kfd/io/source.h"
#include "kfd/mrpt/scan_adapter.h"
#include "kfd/mrpt/stream_filter.h"
#include "kfd/os/cancel.h"
#include "kfd/os/output_paths.h"
#include "kfd/sim/world.h"

namespace kfd {

namespace fs = std::filesystem;

namespace {

// The two outputs' names, checked before anything is written.
NoisyLogSummary outputNames(const NoisyLogOptions& o) {
    NoisyLogSummary sum;
    if (o.input.empty() || o.output.empty()) throw SimulationError("give an input and an output");
    const fs::path out(o.output);
    sum.rawlog = o.output;
    sum.labels = (out.parent_path() / out.stem()).string() + ".labels.csv";
    checkOutputPaths({{"input rawlog", o.input}},
                     {{"output rawlog", sum.rawlog}, {"labels", sum.labels}});
    checkOutputName({"output rawlog", sum.rawlog}, {".rawlog"},
                    "kfd-inject writes an MRPT rawlog (.rawlog)");
    return sum;
}

// An entry of the input as the rawlog holds it (a bag's other topics have no place there).
void writeEntry(GzOutputStream& f, const SourceEntry& e) {
    switch (e.kind) {
        case SourceEntry::Kind::Frame:
            if (e.action) f.write(*e.action);
            f.write(*e.frame);
            break;
        case SourceEntry::Kind::Action:
            f.write(*e.action);
            break;
        case SourceEntry::Kind::Observation:
            f.write(*e.observation);
            break;
        case SourceEntry::Kind::Other:
            f.write(*e.other);
            break;
        case SourceEntry::Kind::Native:  // another topic of a bag: not in a rawlog
            break;
    }
}

}  // namespace

NoisyLogSummary writeNoisyLog(const NoisyLogOptions& o) {
    NoisyLogSummary sum = outputNames(o);
    RealNoiseInjector noise;
    try {
        noise.initialize(o.noise);
    } catch (const ParameterError& e) {
        throw SimulationError(e.what());
    }
    const auto source = openSource(o.input);
    TempOutputFile tmp(sum.rawlog), tmp_labels(sum.labels);
    // Every byte through kfd's checked writers: a full disk is a WriteError naming the file.
    GzOutputStream f(tmp.path(), sum.rawlog, 1);
    OutputFile labels(tmp_labels.path(), sum.labels);
    labels << "scan,timestamp,beam,kind,model\n";

    std::mt19937 rng(o.seed);
    // The one door with no stage: it checks each scan (bad ranges marked invalid, bad geometry
    // skipped) and changes nothing else.
    Pipeline::Params check_only;
    check_only.stages.clear();
    StreamFilter door(check_only);
    Scan core;
    std::vector<NoiseKind> kinds;
    std::vector<NoiseModel> models;
    auto inject = [&](const mrpt::obs::CObservation2DRangeScan::Ptr& scan) {
        const std::size_t k = sum.scans++;
        if (door.process(*scan).skipped != ScanSkipReason::None) return;  // copied unchanged
        toCore(*scan, core);
        for (std::size_t i = 0; i < core.size(); ++i) sum.beams += core.valid[i] ? 1 : 0;
        noise.apply(core, kinds, models, rng);
        const std::string t = std::to_string(core.timestamp);
        for (std::size_t i = 0; i < core.size(); ++i) {
            if (kinds[i] == NoiseKind::Clean) continue;
            scan->setScanRange(i, core.range[i]);
            scan->setScanRangeValidity(i, true);
            labels << std::to_string(k) + ',' + t + ',' + std::to_string(i) + ',' +
                          toString(kinds[i]) + ',' + toString(models[i]) + '\n';
            ++sum.by_kind[static_cast<std::size_t>(kinds[i])];
            ++sum.by_model[static_cast<std::size_t>(models[i])];
        }
    };
    SourceEntry e;
    const double total = static_cast<double>(std::max<std::uint64_t>(1, source->bytesTotal()));
    std::size_t n = 0;
    while (source->next(e)) {
        throwIfCancelled();
        e.forEachScan(inject);
        writeEntry(f, e);
        if (o.on_progress && ++n % std::max<std::size_t>(1, o.progress_every) == 0)
            o.on_progress(static_cast<double>(source->bytesRead()) / total, sum.scans);
    }
    if (sum.scans == 0) throw SimulationError("no 2D scans in " + o.input);
    f.close();  // the trailer, fsync, checked
    labels.close();
    throwIfCancelled();
    tmp.commit();
    tmp_labels.commit();
    if (o.on_progress) o.on_progress(1.0, sum.scans);
    return sum;
}

}  // namespace kfd
