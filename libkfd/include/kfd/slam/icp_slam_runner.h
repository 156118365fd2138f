// ICP-SLAM over a rawlog with a kfd pre-filter in front (the paper's Figure 1).
#pragma once

#include <mrpt/maps/CSimpleMap.h>

#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "kfd/eval/relations.h"
#include "kfd/eval/trajectory.h"
#include "kfd/io/source.h"
#include "kfd/mrpt/scan_record.h"
#include "kfd/os/output_paths.h"
#include "kfd/pipeline/error.h"
#include "kfd/pipeline/pipeline.h"
#include "kfd/slam/icp_slam_logs.h"
#include "kfd/slam/prefilter_modes.h"

namespace kfd {

struct IcpSlamProgress {
    std::size_t entries = 0, scans_in = 0, scans_kept = 0;
    double fraction = 0.0;  // of the input file consumed
};

struct IcpSlamOptions {
    std::string config_file;  // icp-slam .ini: [ICP], [MappingApplication], maps, optional [KFD]
    std::string rawlog;       // any log openSource() reads (rawlog, ROS 1 bag, CARMEN log);
                              // empty: [MappingApplication] rawlog_file
    SourceOptions source;     // a bag's topics and frames
    std::string output_dir;   // empty: [MappingApplication] logOutput_dir
    PrefilterMode mode = PrefilterMode::Kfd;
    /// Odometry and decimate modes only: drop this percentage of the scans (e.g. kfd's drop
    /// rate on the same log). Odometry: the motion thresholds (distance D, angle 30 deg/m x D)
    /// found by bisection; decimate: decimate_keep = 1 - PCT / 100.
    std::optional<double> odometry_target_drop_pct;
    /// Odometry and decimate modes only, instead of a percentage: drop as many scans as this
    /// mode's pipeline drops on the same log with the same options (skip_scans, laser_only),
    /// found by a pre-pass of the pre-filter alone (no ICP; its CPU time is cpu_s_match).
    std::optional<PrefilterMode> match_drop_of;
    /// Skip the first K scans of the log (and every entry before the (K+1)-th scan): they get
    /// no pose and no relation uses them. The repeats of kfd-compare start K = 0, 1, 2, ...
    /// scans later: the same problem, a different chaotic run.
    std::size_t skip_scans = 0;
    /// What a robot without wheel odometry sees: the pre-filter gets no odometry (its guards and
    /// the motion stage see none) and neither does the map builder (odometry observations are
    /// left out; an action-and-frame step gets an empty action).
    bool laser_only = false;
    /// Relations spanning at most this many seconds are "local", the others "long"
    /// (summary.relations_local, relations_long).
    double split_seconds = 10.0;
    std::string relations;           // ground truth (.relations), optional
    double relations_max_dt = 1e-3;  // s, stamp matching tolerance
    std::string ground_truth_tum;    // ground-truth trajectory (TUM), optional: ATE and figure
    /// Keep the built map in the result, for writeIcpSlamReport's final_map.simplemap, map.png,
    /// map_figure.png and report.md (kfd/report/slam_report.h).
    bool write_map = true;
    std::function<void(const IcpSlamProgress&)> on_progress;
};

/// kfd-icp-slam's summary: the door's counters (ScanCounters: scans in, kept, skipped by reason
/// — a skipped scan never reaches ICP and its pose is propagated like a dropped scan's —, bad
/// ranges and odometry, corridor scans, points) and what the SLAM run adds.
struct IcpSlamSummary : ScanCounters {
    PrefilterMode mode = PrefilterMode::Kfd;
    std::string rawlog, output_dir;
    std::size_t entries = 0;
    double dropped_pct = 0.0;             // scans not kept (dropped or skipped), % of scans_in
    double prefilter_us_per_scan = 0.0;   // mean over input scans
    double icp_ms_per_scan = 0.0;         // map-builder time / input scans
    double icp_ms_per_kept_scan = 0.0;    // map-builder time / kept scans
    double cpu_s_total = 0.0;             // process CPU time of the run (I/O included)
    double cpu_s_match = 0.0;             // of which the match_drop_of pre-pass
    std::size_t scans_skipped_start = 0;  // the first skip_scans scans, not in scans_in
    /// Scans MRPT's icp-slam reads no step from, not in scans_in (kfd-filter counts them): in a
    /// sensory frame without an odometry action before it, or between an action and its frame.
    std::size_t scans_without_step = 0;
    /// Scans before [MappingApplication] rawlog_offset (that many file objects), not in scans_in.
    std::size_t scans_before_offset = 0;
    SourceCounters source;  // what the bag or CARMEN source repaired or left out
    bool laser_only = false;
    std::optional<double> target_drop_pct;  // what the odometry or decimate mode matched
    double wall_s_total = 0.0;
    Pipeline::Params pipeline;  // what ran
    std::optional<RelationsError> relations;
    double split_seconds = 10.0;
    /// relations over at most / over more than split_seconds; absent when that subset is empty
    /// or none of it matched (counted in relations_*_count / relations_*_unmatched)
    std::optional<RelationsError> relations_local, relations_long;
    std::size_t relations_local_count = 0, relations_long_count = 0;
    std::optional<double> ate_rmse;  // m, against ground_truth_tum after SE(2) alignment
    std::string relations_file;
    /// ICP's corrections (MRPT's map builder logs each one's goodness, the share of the scan's
    /// points matched): how many ran, how many it rejected (goodness below
    /// minICPgoodnessToAccept: the pose then follows odometry alone) and the median goodness.
    std::size_t icp_runs = 0, icp_rejected = 0;
    double icp_goodness_median = 0.0;
    /// Suspected lost tracks: kLostTrackRejections ICP corrections rejected in a row (the
    /// builder dead-reckons and stops inserting into the map). The stamp (s) of the first
    /// rejection of each such streak.
    std::vector<double> lost_track_stamps;
    /// Scans the pre-filter dropped that went to the map builder all the same because ICP had
    /// rejected its last correction (counted in scans_kept; reason "icp_recovery" in scans.csv).
    std::size_t scans_kept_for_recovery = 0;
    /// Re-matches: after a rejected correction, the scans the pre-filter dropped since ICP's
    /// last accepted one went through ICP in order, then the rejected scan again (rematches
    /// times; rematches_recovered times ICP then accepted it). scans_rematched of those scans
    /// (counted in scans_kept; reason "icp_rematch" in scans.csv).
    std::size_t rematches = 0, rematches_recovered = 0, scans_rematched = 0;
    /// Corrections across scans the pre-filter dropped that fell below kfd's gap check (3/4 of
    /// the recent median goodness; above the configuration's minimum): rejected and
    /// re-matched, not counted in icp_rejected.
    std::size_t gap_checks_failed = 0;
    /// The keyframe guards the run used (0 = off): the [KFD] section's, lowered to the SLAM's
    /// localisation gate (localizationLinDistance, localizationAngDistance) when that is
    /// shorter, so that kfd never drops the scan ICP's gate would have matched.
    double guard_translation_m = 0.0, guard_rotation_deg = 0.0;
    /// The keyframe guards as configured ([KFD] or kfd's defaults), before the gate: where they
    /// differ from the two above, the gate lowered them (reported in summary.json and by
    /// summaryText).
    double guard_translation_m_configured = 0.0, guard_rotation_deg_configured = 0.0;
    /// What the run did not honour, one sentence each naming the configuration key or map (an
    /// icp-slam key kfd-icp-slam ignores: IcpSlamLogParams::fromConfig; a map kind it cannot
    /// save: IcpSlamLogs::finish). The caller shows them; the run went on.
    std::vector<std::string> notices;
};

/// ICP corrections rejected in a row that make a suspected lost track.
inline constexpr std::size_t kLostTrackRejections = 3;

/// Everything a run produced, for the report (kfd/report/slam_report.h) and other callers.
struct IcpSlamResult {
    IcpSlamSummary summary;
    Trajectory trajectory;  // one pose per input scan (time order of the log)
    Trajectory odometry;    // the odometry of every input scan that had one
    Trajectory track;  // the track stage's pose of every scan it saw (laser odometry; kfd's modes)
    std::vector<std::size_t> keyframes;  // indices into `trajectory` of the kept scans
    std::vector<std::size_t> corridor;   // ... of the scans the corridor switch found degenerate
    Trajectory ground_truth;             // ground_truth_tum, sorted by time (empty without it)
    std::optional<mrpt::maps::CSimpleMap> map;  // the built map, with write_map (map_origin's
                                                // frame)
    /// Where the map builder's frame sits in the log's frame (m): (0, 0) unless the log's
    /// absolute odometry starts more than kLocalFrameM from the origin (UTM-like coordinates),
    /// where ICP (MRPT's point maps hold floats: 0.5 m steps at 5e6 m) runs in a frame that
    /// starts at the first odometry position, rounded to the metre. `trajectory`,
    /// log_estimated_path.txt and scans.csv are in the log's frame.
    Pose2D map_origin;
    /// The staged output folder holding what run() wrote; writeIcpSlamReport() adds the report
    /// and commits it (callers without a report call output->commit()). Removed uncommitted
    /// when the last copy of the result goes.
    std::shared_ptr<StagedOutputFolder> output;
};

/// Beyond this distance (m) of the first absolute odometry from the origin, kfd-icp-slam runs the
/// map builder in a local frame (IcpSlamResult::map_origin): a float resolves 1 mm at 10 km.
inline constexpr double kLocalFrameM = 1.0e4;

/// Every file kfd-icp-slam may write into its output folder under a fixed name (checked against
/// the inputs), icp-slam's (IcpSlamLogs) included.
inline constexpr const char* kIcpSlamOutputFiles[] = {"trajectory.tum",
                                                      "log_estimated_path.txt",
                                                      "scans.csv",
                                                      "summary.json",
                                                      "final_map.simplemap",
                                                      "map.png",
                                                      "map_figure.png",
                                                      "report.md",
                                                      "log_odometry_path.txt",
                                                      "log_times.txt",
                                                      "log_MemoryUsage.txt",
                                                      "_finalmap_.simplemap"};

/// The numbered and per-map names of icp-slam's files (IcpSlamLogs): PREFIX, anything, SUFFIX.
/// Existing files of the output folder with such a name are checked against the inputs too.
struct OutputNamePattern {
    const char* prefix;
    const char* suffix;
};
inline constexpr OutputNamePattern kIcpSlamNumberedOutputs[] = {
    {"mapbuild_posepdf_", ".txt"}, {"buildingmap_", ".3Dscene"}, {"_finalmaps_.txt_", ""}};

/// True when `file_name` (no folder) has the form of a kIcpSlamNumberedOutputs name.
bool isIcpSlamNumberedOutput(const std::string& file_name);

/// Bad input, configuration or output (message says which).
class SlamError : public Error {
  public:
    using Error::Error;
};

/// Options that contradict each other (a matched drop rate without a mode that can match, two
/// targets): the caller's usage error (kfd-icp-slam exits 2).
class SlamOptionError : public SlamError {
  public:
    using SlamError::SlamError;
};

/// Runs CMetricMapBuilderICP over a rawlog exactly like MRPT's icp-slam (same config sections,
/// same call sequence), with the pre-filter deciding which scans reach scan matching. A dropped
/// scan in an actions+sensory-frames log is removed from its frame and the frame's odometry
/// action is still processed; in an observations log the scan is skipped and odometry
/// observations are still processed. Every input scan gets a pose (the map builder's estimate,
/// propagated with odometry for dropped scans). Every scan enters through the one door
/// (StreamFilter::process), in every mode (`none` included): a bad geometry skips it (counted,
/// never reaches ICP), bad ranges are marked invalid, and a non-finite odometry reading is left
/// out of the map builder's input. With the denoise key next_scan = true a kept scan waits for
/// the sensor's next scan (StreamFilter's pending scans): its step, and the steps after it, go
/// to the map builder, in order, once the door has finished it (ICP one step later; the last at
/// the end of the log). A log with no scan the door could use (none at all, none
/// after skip_scans, or every one skipped) is a SlamError naming the log and the skip reasons
/// (kfd::noUsableScan), and nothing is written. An exception of MRPT's map builder becomes a
/// SlamError naming the step, its scan's stamp and the log, with MRPT's message
/// (kfd::plainMessage); one while configuring it names the configuration file. Relations given
/// but none matched, or a negative relations_max_dt, are errors (SlamError); contradicting
/// options are a SlamOptionError.
///
/// Checks first that the configuration, the rawlog, the relations and the ground truth are
/// readable (the ground truth and relations are parsed before the run) and that no output file
/// is (or aliases) one of them (PathError). Stops with kfd::Cancelled after
/// kfd::requestCancel(). Writes into a staging folder (kfd::StagedOutputFolder: beside a new
/// output folder, inside an existing one, whose other files are left alone), held by
/// IcpSlamResult::output: trajectory.tum (one pose per input scan, TUM format), icp-slam's files
/// as [MappingApplication] asks (IcpSlamLogs: log_estimated_path.txt, log_odometry_path.txt,
/// log_times.txt, log_MemoryUsage.txt, one line per icp-slam step; the periodic
/// mapbuild_posepdf_NNN.txt and buildingmap_NNNNN.3Dscene; with write_map _finalmap_.simplemap
/// and _finalmaps_.txt_*; the keys it cannot honour are summary.notices) and scans.csv (the
/// door's per-scan records with the scan's pose, kfd/io/scan_csv.h), through kfd's checked
/// writers: a failed write is a WriteError (a ScanCsvError for scans.csv) naming the file's final
/// name and the reason ("cannot write OUT/scans.csv: No space left on device").
/// summary.json, final_map.simplemap, map.png, map_figure.png and report.md are written from
/// the result by writeIcpSlamReport() (kfd/report/slam_report.h).
class IcpSlamRunner {
  public:
    IcpSlamResult run(const IcpSlamOptions& opts);
};

}  // namespace kfd
