#include "kfd/pipeline/stage_outputs.h"

#include <algorithm>

#include "kfd/pipeline/error.h"
#include "kfd/pipeline/pipeline.h"
#include "kfd/pipeline/stage_registry.h"

namespace kfd {

StageOutputs::StageOutputs(const std::vector<std::string>& stages, const StageRegistry& registry) {
    const std::vector<std::string> instances = instanceNames(stages);  // "denoise", "denoise_2"
    for (std::size_t i = 0; i < stages.size(); ++i) {
        const std::string& stage = stages[i];
        const StageInfo* info = registry.find(stage);
        if (!info) throw Error("unknown stage '" + stage + "'", "stages");
        Bound b;  // the how-manieth listing of this stage
        b.stage = stage;
        b.occurrence = static_cast<std::size_t>(
            std::count(stages.begin(), stages.begin() + static_cast<std::ptrdiff_t>(i), stage));
        const std::string prefix = b.occurrence ? instances[i] + "." : std::string();
        for (const StageColumn& c : info->columns) {
            std::string name = prefix + c.name;
            if (std::find(names_.begin(), names_.end(), name) != names_.end())
                name = stage + "." + name;
            names_.push_back(name);
            column_stage_.push_back(b);
            columns_.push_back(c);
        }
        for (const StageCounter& c : info->counters) {
            counter_stage_.push_back(b);
            counters_.push_back(c);
            zero_totals_.push_back({instances[i], prefix + c.name, c.help, 0.0});
        }
    }
}

const StageReport* StageOutputs::reportOf(const ScanReport& r, const Bound& b) {
    std::size_t n = 0;
    for (const StageReport& s : r)
        if (b.stage == s.name && n++ == b.occurrence) return &s;
    return nullptr;
}

std::string StageOutputs::cellAt(const ScanReport& report, std::size_t i) const {
    const StageReport* s = reportOf(report, column_stage_[i]);
    return s ? columns_[i].cell(*s) : columns_[i].absent;
}

std::string StageOutputs::cells(const ScanReport& report) const {
    std::string line;
    for (std::size_t i = 0; i < columns_.size(); ++i) line += ',' + cellAt(report, i);
    return line;
}

std::string StageOutputs::cell(const ScanReport& report, std::string_view name) const {
    const auto it = std::find(names_.begin(), names_.end(), name);
    return it == names_.end() ? std::string()
                              : cellAt(report, static_cast<std::size_t>(it - names_.begin()));
}

void StageOutputs::count(const ScanReport& report, std::vector<StageTotal>& totals) const {
    for (std::size_t i = 0; i < counters_.size() && i < totals.size(); ++i) {
        if (counters_[i].kept_only && !report.keep) continue;
        if (const StageReport* s = reportOf(report, counter_stage_[i]))
            totals[i].value += counters_[i].value(*s);
    }
}

double totalOf(const std::vector<StageTotal>& totals, std::string_view name) {
    for (const StageTotal& t : totals)
        if (t.name == name) return t.value;
    return 0.0;
}

std::vector<std::string> stageCounterLines(const std::vector<StageTotal>& totals) {
    std::vector<std::string> lines;
    std::string stage, line;
    const auto flush = [&] {
        if (!line.empty()) lines.push_back(stage + ": " + line);
        line.clear();
    };
    for (const StageTotal& t : totals) {
        if (t.stage != stage) flush();
        stage = t.stage;
        if (t.value == 0.0) continue;
        line += (line.empty() ? "" : "; ") + format("%g ", t.value) + t.help;
    }
    flush();
    return lines;
}

}  // namespace kfd
