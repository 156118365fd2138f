#include "kfd/core/pipeline.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>

namespace kfd {

bool DistanceStage::filter(Scan& scan, ScanReport& report) {
    report.distance = algo_.filter(scan);
    return true;
}

bool KeyframeStage::filter(Scan& scan, ScanReport& report) {
    report.keyframe = algo_.filter(scan);
    report.keyframe_evaluated = true;
    return report.keyframe.keyframe;
}

bool DenoiseStage::filter(Scan& scan, ScanReport& report) {
    report.denoise = algo_.filter(scan);
    report.denoised = true;
    return true;
}

bool MotionStage::filter(Scan& scan, ScanReport&) {
    return algo_.keep(scan.timestamp, scan.odometry);
}

bool DbscanStage::filter(Scan& scan, ScanReport& report) {
    report.dbscan = algo_.filter(scan);
    return true;
}

bool RadiusStage::filter(Scan& scan, ScanReport& report) {
    report.radius = algo_.filter(scan);
    return true;
}

bool SorStage::filter(Scan& scan, ScanReport& report) {
    report.sor = algo_.filter(scan);
    return true;
}

void Pipeline::initialize(const Params& p) {
    // Validate every stage's parameters, listed or not, so a bad value in a config file is
    // reported even while its stage is switched off.
    DistanceFilter{p.distance};
    KeyframeSelector{p.keyframe};
    Denoiser{p.denoise};
    MotionFilter{p.motion};
    DbscanFilter{p.dbscan};
    RadiusOutlierFilter{p.radius};
    StatisticalOutlierFilter{p.sor};
    std::vector<std::unique_ptr<ScanFilter>> stages;
    for (const auto& name : p.stages) {
        for (const auto& s : stages)
            if (name == s->name())
                throw std::invalid_argument("pipeline: stage '" + name + "' listed twice");
        if (name == "distance") {
            auto s = std::make_unique<DistanceStage>();
            s->initialize(p.distance);
            stages.push_back(std::move(s));
        } else if (name == "keyframe") {
            auto s = std::make_unique<KeyframeStage>();
            s->initialize(p.keyframe);
            stages.push_back(std::move(s));
        } else if (name == "denoise") {
            auto s = std::make_unique<DenoiseStage>();
            s->initialize(p.denoise);
            stages.push_back(std::move(s));
        } else if (name == "motion") {
            auto s = std::make_unique<MotionStage>();
            s->initialize(p.motion);
            stages.push_back(std::move(s));
        } else if (name == "dbscan") {
            auto s = std::make_unique<DbscanStage>();
            s->initialize(p.dbscan);
            stages.push_back(std::move(s));
        } else if (name == "radius") {
            auto s = std::make_unique<RadiusStage>();
            s->initialize(p.radius);
            stages.push_back(std::move(s));
        } else if (name == "sor") {
            auto s = std::make_unique<SorStage>();
            s->initialize(p.sor);
            stages.push_back(std::move(s));
        } else {
            throw std::invalid_argument(
                "pipeline: unknown stage '" + name +
                "' (known: distance, keyframe, denoise, motion, dbscan, radius, sor)");
        }
    }
    stages_ = std::move(stages);
    params_ = p;
}

void Pipeline::add(std::unique_ptr<ScanFilter> stage) {
    if (!stage) throw std::invalid_argument("pipeline: null stage");
    stages_.push_back(std::move(stage));
}

ScanReport Pipeline::process(Scan& scan) {
    const auto t0 = std::chrono::steady_clock::now();
    ScanReport report;
    if (scan.valid.size() != scan.range.size())
        throw std::invalid_argument("scan: range and valid sizes differ");
    report.points_in = scan.countValid();
    for (auto& stage : stages_) {
        if (!stage->filter(scan, report)) {
            report.keep = false;
            report.dropped_by = stage->name();
            break;
        }
    }
    report.points_out = scan.countValid();
    report.microseconds =
        std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count();
    return report;
}

void Pipeline::reset() {
    for (auto& s : stages_) s->reset();
}

const Clusters* Pipeline::lastClusters() const {
    for (const auto& s : stages_)
        if (const auto* d = dynamic_cast<const DenoiseStage*>(s.get()))
            return &d->denoiser().clusters();
    return nullptr;
}

}  // namespace kfd
