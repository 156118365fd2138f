#include "kfd/pipeline/pipeline.h"

#include <algorithm>
#include <chrono>
#include <string>

#include "kfd/algorithms/surface_run.h"

namespace kfd {

PipelineParams::PipelineParams(const PipelineParams& o) : stages(o.stages) {
    for (const auto& e : o.entries_) entries_.push_back(Entry{e.stage, e.params->clone()});
}

PipelineParams& PipelineParams::operator=(const PipelineParams& o) {
    if (this != &o) {
        PipelineParams copy(o);
        *this = std::move(copy);
    }
    return *this;
}

StageParams& PipelineParams::at(const StageInfo& stage) { return at(stage, stage.name); }

StageParams& PipelineParams::at(const StageInfo& stage, std::string_view instance) {
    if (StageParams* p = find(instance)) return *p;
    entries_.push_back(Entry{std::string(instance), stage.defaults()});
    return *entries_.back().params;
}

bool PipelineParams::lists(std::string_view stage) const {
    return std::find(stages.begin(), stages.end(), stage) != stages.end();
}

std::vector<std::string> instanceNames(const std::vector<std::string>& stages) {
    std::vector<std::string> names;
    for (std::size_t i = 0; i < stages.size(); ++i) {
        std::size_t n = 1;
        for (std::size_t j = 0; j < i; ++j) n += stages[j] == stages[i];
        names.push_back(n == 1 ? stages[i] : stages[i] + "_" + std::to_string(n));
    }
    return names;
}

StageParams* PipelineParams::find(std::string_view name) {
    for (auto& e : entries_)
        if (e.stage == name) return e.params.get();
    return nullptr;
}

const StageParams* PipelineParams::find(std::string_view name) const {
    for (const auto& e : entries_)
        if (e.stage == name) return e.params.get();
    return nullptr;
}

void Pipeline::initialize(const Params& p, const StageRegistry& registry) {
    if (p.stages.size() > ScanReport::kMaxStages)
        throw ParameterError("stages",
                             "more than " + std::to_string(ScanReport::kMaxStages) + " stages");
    std::vector<const StageInfo*> infos;
    for (const auto& name : p.stages) {
        const StageInfo* info = registry.find(name);
        if (!info)
            throw ParameterError("stages", "pipeline: unknown stage '" + name +
                                               "' (known: " + registry.names() + ")");
        infos.push_back(info);  // a stage may be listed twice: its second instance is name_2
    }
    // Set but not listed: validated here (listed stages validate when they are built).
    for (const auto& e : p.entries()) {
        const StageInfo* info = registry.find(e.stage);
        bool listed = false;
        for (const auto* s : infos) listed = listed || s == info;
        if (info && !listed) info->validate(*e.params);
    }
    std::vector<std::unique_ptr<Stage>> stages;
    const std::vector<std::string> instances = instanceNames(p.stages);
    for (std::size_t i = 0; i < infos.size(); ++i) {
        const StageParams* set = p.find(instances[i]);
        stages.push_back(set ? infos[i]->create(*set) : infos[i]->create(*infos[i]->defaults()));
    }
    finished_ = false;
    if (held_) finishHeld(nullptr);  // by the stages that held it; finished() returns it
    stages_ = std::move(stages);
    params_ = p;
    registry_ = &registry;
}

void Pipeline::add(std::unique_ptr<Stage> stage) {
    if (!stage) throw Error("pipeline: null stage");
    if (stages_.size() >= ScanReport::kMaxStages)
        throw Error("pipeline: more than " + std::to_string(ScanReport::kMaxStages) + " stages");
    stages_.push_back(std::move(stage));
}

namespace {

// Runs one stage on `scan` (its held scan's finish() when `next` is given), and, when it
// removed returns as noise, measures the longest removed run that looks like a surface
// (StageReport::surface_m) against its input flags, copied to `before`.
bool runStage(Stage& stage, Scan& scan, StageReport& sr, const ScanReport& report,
              std::vector<std::uint8_t>& before, bool finishing, const Scan* next) {
    before.assign(scan.valid.begin(), scan.valid.end());  // no allocation once grown
    const bool keep =
        finishing ? stage.finish(scan, sr, report, next) : stage.process(scan, sr, report);
    if (sr.noise && sr.points_removed > 0 && before.size() == scan.size()) {
        const SurfaceRun run = longestRemovedSurface(scan, before.data());
        sr.surface_beams = run.beams;
        sr.surface_m = run.length_m;
    }
    return keep;
}

// A stage's end: its time since `t` (then `t` moves on) and, when it dropped the scan, the
// report says so. Returns `keep`.
bool endStage(const Stage& stage, bool keep, StageReport& sr, ScanReport& report,
              std::chrono::steady_clock::time_point& t) {
    const auto now = std::chrono::steady_clock::now();
    sr.microseconds = std::chrono::duration<double, std::micro>(now - t).count();
    t = now;
    if (!keep) {
        sr.dropped = true;
        report.keep = false;
        report.dropped_by = stage.name();
    }
    return keep;
}

}  // namespace

ScanReport Pipeline::process(Scan& scan) {
    using Clock = std::chrono::steady_clock;
    const auto t0 = Clock::now();
    ScanReport report;
    if (scan.valid.size() != scan.range.size())
        throw ScanError("scan: range and valid sizes differ");
    {
        ScanGeometry g = scan.geometry;
        g.beams = scan.range.size();  // the stages follow the data's length
        const ScanSkipReason why = checkGeometry(g);
        if (why != ScanSkipReason::None)
            throw ScanError(std::string("scan: unusable geometry (") + toString(why) + ")");
    }
    finished_ = false;
    report.points_in = scan.countValid();
    // One clock read per stage: each stage's end is the next one's start.
    auto t = t0;
    for (std::size_t i = 0; i < stages_.size(); ++i) {
        Stage& stage = *stages_[i];
        // This scan reached the stage holding the one before: that one is finished first,
        // with this scan as its next.
        if (held_ && i == held_stage_) t += finishHeld(&scan);  // not this scan's time
        StageReport& sr = report.stage_reports[report.stage_count++];
        sr.name = stage.name();
        if (stage.defers()) {  // held: finished by the next scan (or finish(), reset())
            held_scan_ = scan;
            held_stage_ = i;
            held_ = true;
            --report.stage_count;
            report.pending = true;
            break;
        }
        const bool keep = runStage(stage, scan, sr, report, before_, false, nullptr);
        if (!keep) {  // the later stages see the dropped scan (Stage::observeDropped)
            for (std::size_t j = i + 1; j < stages_.size(); ++j) {
                if (held_ && j == held_stage_) t += finishHeld(&scan);
                stages_[j]->observeDropped(scan, report);
            }
        }
        if (!endStage(stage, keep, sr, report, t)) break;
    }
    if (stages_.empty()) {
        report.microseconds = std::chrono::duration<double, std::micro>(Clock::now() - t0).count();
    } else {  // the sum of the stages' times, so that they add up exactly to the chain's time
        for (std::size_t i = 0; i < report.stage_count; ++i)
            report.microseconds += report.stage_reports[i].microseconds;
    }
    report.points_out = scan.countValid();
    // The stages that ran hear the verdict (Stage::decided); a held scan is kept.
    for (std::size_t i = 0; i < report.stage_count; ++i) stages_[i]->decided(scan, report.keep);
    if (report.pending) held_report_ = report;
    return report;
}

// Runs the held scan through the holding stage (with `next` as its next scan) and the later
// ones; its report becomes finished().
std::chrono::steady_clock::duration Pipeline::finishHeld(const Scan* next) {
    using Clock = std::chrono::steady_clock;
    const auto t0 = Clock::now();
    held_ = false;
    ScanReport& report = held_report_;
    report.pending = false;
    auto t = Clock::now();
    for (std::size_t i = held_stage_; i < stages_.size(); ++i) {
        Stage& stage = *stages_[i];
        StageReport& sr = report.stage_reports[report.stage_count++];
        sr.name = stage.name();
        const bool keep = runStage(stage, held_scan_, sr, report, before_, i == held_stage_, next);
        if (!keep) {
            for (std::size_t j = i + 1; j < stages_.size(); ++j)
                stages_[j]->observeDropped(held_scan_, report);
        }
        const bool kept = endStage(stage, keep, sr, report, t);
        report.microseconds += sr.microseconds;
        if (!kept) break;
    }
    report.points_out = held_scan_.countValid();
    // Handed out by finished(); held_scan_ takes the old buffers (no allocation once grown).
    std::swap(held_scan_, finished_scan_);
    finished_report_ = report;
    finished_ = true;
    return Clock::now() - t0;
}

const Scan* Pipeline::finished(ScanReport& report) const {
    if (!finished_) return nullptr;
    report = finished_report_;
    return &finished_scan_;
}

bool Pipeline::finish() {
    finished_ = false;
    if (!held_) return false;
    finishHeld(nullptr);
    return true;
}

void Pipeline::reset() {
    finished_ = false;
    if (held_) finishHeld(nullptr);
    for (auto& s : stages_) s->reset();
}

ScanGeometry Pipeline::outputGeometry(const ScanGeometry& in) const {
    ScanGeometry g = in;
    for (const auto& s : stages_) g = s->outputGeometry(g);
    return g;
}

const Clusters* Pipeline::lastClusters() const {
    for (const auto& s : stages_)
        if (const Clusters* c = s->clusters()) return c;
    return nullptr;
}

}  // namespace kfd
