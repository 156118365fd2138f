// What the one door for a scan (StreamFilter::process) says about each scan and about a run:
// one per-scan record and one set of counters, shared by every driver (kfd-filter, kfd-icp-slam
// and its pre-pass, kfd-render, the simulator's tools).
#pragma once

#include <cstddef>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "kfd/algorithms/odometry_check.h"
#include "kfd/pipeline/scan.h"
#include "kfd/pipeline/stage.h"
#include "kfd/pipeline/stage_outputs.h"

namespace kfd {

/// One scan as the door saw it: the row of the per-scan CSV (kfd/io/scan_csv.h documents
/// the columns). A skipped scan (bad geometry) has `skipped` set, points_in = its beam count
/// and zeros elsewhere.
struct ScanRecord {
    std::size_t index = 0;  // 0-based, every scan given to the door (skipped ones included)
    double stamp = 0.0;     // s; 0 when the scan has no stamp (kfd::stampForOutput)
    std::string sensor;     // the scan's sensor label
    bool kept = false;      // a keyframe: the scan goes on (to the output, to ICP)
    ScanSkipReason skipped = ScanSkipReason::None;  // not None: bad geometry, never ran
    const char* reason = "";    // keyframe reason ("view_change", "similar", ...), else "kept"
                                // or the stage that dropped it, or "skipped:<why>" (static text)
    std::size_t points_in = 0;  // valid beams entering the pipeline
    std::size_t removed_noise = 0;  // by the denoising stages (StageReport::noise)
    double surface_m = 0.0;      // the longest removed run that looks like a surface (m; 0: none)
    std::size_t points_out = 0;  // valid beams leaving the pipeline
    double microseconds = 0.0;   // time in the pipeline's stages
    /// The stages' reports (empty for a skipped scan): the listed stages' own columns are
    /// formatted from it when the row is written (kfd/pipeline/stage_outputs.h;
    /// StreamFilter::outputs().cell(record.report, "corridor") reads one by name).
    ScanReport report;
    std::optional<Pose2D> odometry;  // the odometry the door was given, after its check
    /// kfd-icp-slam: ICP's goodness when the map builder corrected this (kept) scan's pose,
    /// else NaN; icp_rejected when the builder rejected that correction (below its minimum).
    double icp_goodness = std::numeric_limits<double>::quiet_NaN();
    bool icp_rejected = false;
};

/// Counters of a run through the door, filled by StreamFilter::process for every scan: the
/// figures both kfd-filter's and kfd-icp-slam's summaries report.
struct ScanCounters {
    std::size_t scans_in = 0;       // every scan given to the door
    std::size_t scans_kept = 0;     // keyframes
    std::size_t scans_dropped = 0;  // dropped by a stage (not the skipped ones)
    /// Skipped: bad geometry (kfd/mrpt/scan_check.h), never reached a stage; dropped from the
    /// outputs like a non-keyframe, not counted in scans_dropped.
    std::size_t scans_skipped = 0;
    std::size_t skipped_by_reason[kScanSkipReasons] = {};  // indexed by ScanSkipReason
    std::size_t beams_bad_range = 0;   // beams marked invalid: NaN, +-inf, negative, huge range
    std::size_t odometry_bad = 0;      // scans whose odometry was not finite (used as unknown)
    std::size_t stamps_backwards = 0;  // scans stamped before their sensor's previous scan
    std::size_t geometry_resets = 0;   // a sensor's geometry changed: its state was reset
    /// Sensors whose state was dropped to keep at most StreamFilter::maxSensors() (the least
    /// recently seen first; a held scan finished first): a stream of ever new sensor names.
    std::size_t sensors_evicted = 0;
    /// The largest share of a kept scan's valid returns the denoising stages removed (0-1).
    double max_removed_noise_share = 0.0;
    std::size_t points_in = 0;             // valid beams of the scans that ran
    std::size_t points_removed_noise = 0;  // by the denoising stages, in kept scans
    std::size_t points_removed = 0;        // points_in - points_out over the kept scans
    double filter_seconds = 0.0;           // time inside the pipeline's stages
    /// The listed stages' own counters (kfd/pipeline/stage_outputs.h), in pipeline order.
    std::vector<StageTotal> stage_totals;
    /// Scans per ScanRecord::reason ("covered", "view_change", "motion", ...), first seen first.
    std::vector<std::pair<std::string, std::size_t>> reasons;
    /// The kept scans whose denoisers removed the largest shares of their returns, largest
    /// first (at most kMostRemoved): where to look first (kfd-render --index).
    struct Removal {
        std::size_t index = 0;    // ScanRecord::index
        double stamp = 0.0;       // s
        std::size_t removed = 0;  // noise points removed
        std::size_t usable = 0;   // returns the denoisers saw
        double share() const { return usable ? double(removed) / double(usable) : 0.0; }
    };
    static constexpr std::size_t kMostRemoved = 5;
    std::vector<Removal> most_removed;
    /// Kept scans where a denoising stage removed a run of returns that looks like a surface
    /// (a straight run, kfd/algorithms/surface_run.h), and the longest such runs, longest
    /// first (at most kMostRemoved): a piece of wall removed as noise is found without
    /// rendering every keyframe.
    struct SurfaceRemoval {
        std::size_t index = 0;  // ScanRecord::index
        double stamp = 0.0;     // s
        double length_m = 0.0;  // the run's length
    };
    std::size_t scans_surface_removed = 0;
    std::vector<SurfaceRemoval> surface_removed;
    /// The stage counter called `name`, 0 when no listed stage declares it.
    double stageTotal(std::string_view name) const { return totalOf(stage_totals, name); }

    /// Dropped and skipped scans, in % of scans_in.
    double notKeptPercent() const {
        return scans_in ? 100.0 * static_cast<double>(scans_in - scans_kept) /
                              static_cast<double>(scans_in)
                        : 0.0;
    }
    /// Dropped scans (not the skipped ones), in % of scans_in.
    double droppedPercent() const {
        return scans_in ? 100.0 * static_cast<double>(scans_dropped) / static_cast<double>(scans_in)
                        : 0.0;
    }
};

}  // namespace kfd
