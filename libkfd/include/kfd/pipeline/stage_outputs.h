// What a stage reports per scan, declared beside its keys: its columns of the per-scan CSV and
// its counters of a run (summaries, summary.json). The door builds the CSV rows and the
// counters from the declarations of the stages a pipeline lists, so a new diagnostic is one
// declaration in its stage's file (std only).
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "kfd/pipeline/format.h"
#include "kfd/pipeline/stage.h"

namespace kfd {

class StageRegistry;

/// One per-scan column of a stage: its CSV header, its meaning with unit, and its cell, read
/// from the stage's report. A stage that did not run for a scan (an earlier one dropped it, or
/// it was skipped) gets `absent`.
struct StageColumn {
    std::string name;    // CSV header, e.g. "p_common"
    std::string help;    // meaning and unit
    std::string absent;  // the cell when the stage did not run for the scan
    std::function<std::string(const StageReport&)> cell;
};

/// One counter of a stage over a run: its summary.json key, its meaning, the scans it counts
/// (every scan the stage ran on, or the kept ones only) and a scan's contribution.
struct StageCounter {
    std::string name;        // summary.json key, e.g. "scans_corridor"
    std::string help;        // what it counts, as the summaries print it
    bool kept_only = false;  // counted over kept scans only
    std::function<double(const StageReport&)> value;
};

/// A column over the stage's diagnostics D: `fmt` applied to get(d); `absent` is the cell of
/// a default D (a stage that did not run reads as one that found nothing).
template <class D, class Get>
StageColumn diagnosticColumn(std::string name, std::string help, const char* fmt, Get get) {
    StageColumn c;
    c.name = std::move(name);
    c.help = std::move(help);
    c.absent = format(fmt, get(D{}));
    c.cell = [fmt, get, absent = c.absent](const StageReport& r) {
        const D* d = r.diagnostics<D>();
        return d ? format(fmt, get(*d)) : absent;
    };
    return c;
}

/// A counter over the stage's diagnostics D (scans without them count 0).
template <class D, class Get>
StageCounter diagnosticCounter(std::string name, std::string help, bool kept_only, Get get) {
    StageCounter c;
    c.name = std::move(name);
    c.help = std::move(help);
    c.kept_only = kept_only;
    c.value = [get](const StageReport& r) {
        const D* d = r.diagnostics<D>();
        return d ? static_cast<double>(get(*d)) : 0.0;
    };
    return c;
}

/// One counter's total over a run.
struct StageTotal {
    std::string stage;  // the stage as listed ("view_keyframe"; "denoise_2" for a second one)
    std::string name;   // the counter's key ("scans_corridor"; "denoise_2.<key>")
    std::string help;
    double value = 0.0;
};

/// The total called `name` in `totals` (0 when none is).
double totalOf(const std::vector<StageTotal>& totals, std::string_view name);

/// The summaries' lines on the stages' counters: one per stage with a counter above 0,
/// "view_keyframe: 12 scans the corridor switch found degenerate; 3 keyframes ...".
std::vector<std::string> stageCounterLines(const std::vector<StageTotal>& totals);

/// The declared outputs of one pipeline (its listed stages, in order): the CSV header's stage
/// part, each scan's cells and the run's counters. A stage listed twice gets its columns and
/// counters a second time, named "<stage>_2.<name>"; a column name two stages declare is kept
/// by the first and prefixed "<stage>." in the second.
class StageOutputs {
  public:
    StageOutputs() = default;
    /// kfd::Error when a stage is not in `registry`.
    StageOutputs(const std::vector<std::string>& stages, const StageRegistry& registry);

    /// The stage columns' names, in order.
    const std::vector<std::string>& columns() const { return names_; }
    /// ",cell,cell,..." for one scan (every stage column; `absent` for a stage that did not
    /// run, e.g. every one of a skipped scan, whose report is empty).
    std::string cells(const ScanReport& report) const;
    /// The cell of column `name` for one scan ("" when there is no such column).
    std::string cell(const ScanReport& report, std::string_view name) const;

    /// Every counter of the listed stages, in order, at 0.
    const std::vector<StageTotal>& zeroTotals() const { return zero_totals_; }
    /// Adds one scan that ran through the pipeline (kept or dropped) to `totals` (as made by
    /// zeroTotals()).
    void count(const ScanReport& report, std::vector<StageTotal>& totals) const;

  private:
    struct Bound {  // a declaration bound to the n-th report of the stage called `stage`
        std::string stage;
        std::size_t occurrence = 0;
    };
    static const StageReport* reportOf(const ScanReport& r, const Bound& b);
    std::string cellAt(const ScanReport& report, std::size_t column) const;

    std::vector<std::string> names_;
    std::vector<Bound> column_stage_;
    std::vector<StageColumn> columns_;
    std::vector<Bound> counter_stage_;
    std::vector<StageCounter> counters_;
    std::vector<StageTotal> zero_totals_;
};

}  // namespace kfd
