// Filtering a whole rawlog file (the logic behind kfd-filter), streaming object by object.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "kfd/io/bag_writer.h"
#include "kfd/io/rawlog_source.h"
#include "kfd/mrpt/scan_record.h"
#include "kfd/mrpt/stream_filter.h"
#include "kfd/pipeline/pipeline.h"

namespace kfd {

struct RawlogProgress {
    std::uint64_t bytes_read = 0;   // compressed bytes consumed
    std::uint64_t bytes_total = 0;  // input file size
    std::size_t objects = 0;
    std::size_t scans_in = 0;
    std::size_t scans_kept = 0;
};

struct RawlogFilterOptions {
    std::string input;      // any log openSource() reads: rawlog, ROS 1 bag, CARMEN log
    std::string output;     // by its name: .rawlog, .bag (a filtered bag: input must be a
                            // bag), .clf/.log[.gz] (a CARMEN log); any other name is refused.
                            // Written to a temporary file, renamed on success
    SourceOptions source;   // a bag's topics and frames
    BagWriterOptions bag;   // a bag output's compression and removed-point mark
    std::string stats_csv;  // optional per-scan CSV (kfd/io/scan_csv.h)
    Pipeline::Params pipeline;
    int compress_level = 1;   // gzip level of the output (0 = store, 9 = smallest)
    bool laser_only = false;  // ignore the log's odometry in kfd's decisions (it stays in the
                              // output): StreamFilter::setLaserOnly
    /// Called about every `progress_every` objects and once at the end.
    std::function<void(const RawlogProgress&)> on_progress;
    std::size_t progress_every = 2000;
};

/// What the log's first sensor is, measured from its scans: the parameters the evidence
/// denoiser derives (resolution from the geometry, range noise from the residuals) and the
/// scan rate (from the stamps of all its scans, kfd::ScanRateMeter).
struct SensorSummary {
    std::string label;
    std::size_t beams = 0;
    double aperture_deg = 0.0;
    double resolution_deg = 0.0;
    double rate_hz = 0.0;            // mean over the log: (scans - 1) / span; 0 = not known
    double median_interval_s = 0.0;  // s, between consecutive scans; 0 = not known
    /// The evidence denoiser's range noise at the last keyframe (0 = that denoiser did not run):
    /// the value used, the scans' residuals' own estimate before the floor (0 = nothing
    /// measured), the floor (min_sigma_m) and whether sigma_m fixed it (nothing measured).
    double range_noise_m = 0.0;
    double range_noise_measured_m = 0.0;
    double range_noise_floor_m = 0.0;
    bool range_noise_configured = false;
    bool odometry = false;  // the log carries odometry (temporal evidence uses it)
};

/// kfd-filter's summary: the door's counters (ScanCounters: scans in, kept, dropped, skipped by
/// reason, bad ranges and odometry, corridor scans, points) and what the file layer adds.
struct RawlogFilterSummary : ScanCounters {
    std::string layout;  // "actions+sensory-frames", "observations", or "mixed";
                         // for a bag or CARMEN input, what was read from it
    LogFormat input_format = LogFormat::Rawlog;
    LogFormat output_format = LogFormat::Rawlog;
    std::size_t points_marked = 0;   // bag output: removed points written as NaN / +Inf
    std::string output_compression;  // bag output: "none", "lz4", "bz2" or "zstd" (chunks)
    /// Bag input: scan topics kfd does not read (MultiEchoLaserScan), copied unfiltered to a
    /// bag output ("TOPIC (TYPE, N messages)").
    std::vector<std::string> unread_scans;
    std::size_t messages_left_out = 0;  // .db3/.mcap of a ROS 1 bag: messages of types kfd
                                        // cannot write as ROS 2 (not LaserScan, Odometry, tf)
    std::size_t objects_in = 0;         // top-level objects read (a CARMEN log: lines; a bag:
                                        // messages)
    std::size_t objects_converted = 0;  // MRPT objects made of them (a rawlog: = objects_in)
    std::size_t objects_out = 0;        // top-level objects written
    std::size_t objects_dropped = 0;    // sensory frames / observations dropped whole
    std::size_t actions_merged = 0;     // odometry actions composed into a later kept action
    std::size_t sensors = 0;
    SensorSummary sensor;       // the first sensor, as measured from its scans
    SourceCounters source;      // what the bag or CARMEN source repaired or left out
    double wall_seconds = 0.0;  // whole run, I/O included
};

/// Reads `input` object by object (never loading it whole), runs every 2D range scan through a
/// StreamFilter, and writes every other object unchanged and in order. A bag or CARMEN input is
/// read through its source (kfd/io/source.h): a rawlog output then holds the scans and the
/// odometry in the observations layout, the bag's other topics left out. A bag output (the
/// output's name ends in .bag; the input must be a bag) copies every message of the input in
/// order, except the dropped scans; a kept scan keeps every field, its removed points written
/// as NaN or +Inf (BagWriterOptions::removed, REP 117). A CARMEN output (.clf, .log, .clf.gz,
/// .log.gz; any input) holds the kept scans as FLASER/RLASER lines and the odometry as ODOM
/// lines, in input order (kfd/io/carmen_writer.h: removed points as 0, "no reading"); every
/// other object is left out, and a kept scan without odometry is a RawlogError (a FLASER line
/// carries the odometry). Any other output name (not .rawlog) is a RawlogError listing the
/// formats, before anything is read or written. Non-keyframe scans are
/// removed; a sensory frame left empty is dropped and its odometry action is composed into the
/// next kept action, so the output's odometry still adds up. Every scan goes through the one
/// door (StreamFilter::process); a scan it skips (beam count outside [2, 65 536], aperture not
/// finite, <= 0 or > 2*pi) is removed from the output exactly like a non-keyframe, counted in
/// scans_skipped and skipped_by_reason, and its stats row has reason "skipped:<reason>"; the
/// run goes on. Beams with a NaN, infinite, negative or huge range
/// are marked invalid in the output (counted in beams_bad_range). A log with no scan the door
/// could use (none at all, or every one skipped) is a RawlogError naming the log and the skip
/// reasons (kfd::noUsableScan), and no output is left. The input is never modified;
/// on any error no output file is left behind: the output and the stats CSV are written under
/// temporary names beside them through kfd's checked writers (GzOutputStream, BagWriter,
/// ScanCsvWriter), both checked when complete (the gzip trailer and the bag index read back,
/// sizes, fsync) and only then renamed. Before anything is written, an output or stats path
/// that is (or aliases) the input or the other output, or that exists and is not a regular
/// file, is refused (a RawlogError from kfd::checkOutputPaths, kfd/os/output_paths.h). A
/// failed write is a RawlogError "cannot write OUT: No space left on device". Stops with
/// kfd::Cancelled after kfd::requestCancel() (kfd/os/cancel.h). Throws RawlogError,
/// ConfigError or Cancelled.
class RawlogFilter {
  public:
    RawlogFilterSummary run(const RawlogFilterOptions& opts);
};

}  // namespace kfd
