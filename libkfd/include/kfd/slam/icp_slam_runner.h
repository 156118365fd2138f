// ICP-SLAM over a rawlog with a kfd pre-filter in front (the paper's Figure 1).
#pragma once

#include <mrpt/maps/CSimpleMap.h>

#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "kfd/core/error.h"
#include "kfd/core/output_paths.h"
#include "kfd/core/pipeline.h"
#include "kfd/eval/relations.h"
#include "kfd/eval/trajectory.h"
#include "kfd/slam/prefilter_modes.h"

namespace kfd {

struct IcpSlamProgress {
    std::size_t entries = 0, scans_in = 0, scans_kept = 0;
    double fraction = 0.0;  // of the input file consumed
};

struct IcpSlamOptions {
    std::string config_file;  // icp-slam .ini: [ICP], [MappingApplication], maps, optional [KFD]
    std::string rawlog;       // empty: [MappingApplication] rawlog_file
    std::string output_dir;   // empty: [MappingApplication] logOutput_dir
    PrefilterMode mode = PrefilterMode::Kfd;
    /// Odometry mode only: choose the motion thresholds (distance D, angle 30 deg/m x D) so
    /// that this percentage of scans is dropped (e.g. kfd's drop rate on the same log).
    std::optional<double> odometry_target_drop_pct;
    std::string relations;           // ground truth (.relations), optional
    double relations_max_dt = 1e-3;  // s, stamp matching tolerance
    std::string ground_truth_tum;    // ground-truth trajectory (TUM), optional: ATE and figure
    /// Keep the built map in the result, for writeIcpSlamReport's final_map.simplemap, map.png,
    /// map_figure.png and report.md (kfd/report/slam_report.h).
    bool write_map = true;
    std::function<void(const IcpSlamProgress&)> on_progress;
};

struct IcpSlamSummary {
    PrefilterMode mode = PrefilterMode::Kfd;
    std::string rawlog, output_dir;
    std::size_t entries = 0;
    std::size_t scans_in = 0, scans_kept = 0;
    /// Scans skipped by kfd::checkScan (bad geometry): in scans_in, never reached ICP; scans.csv
    /// reason "skipped:<reason>"; their pose is propagated like a dropped scan's.
    std::size_t scans_skipped = 0;
    std::size_t skipped_by_reason[kScanSkipReasons] = {};  // indexed by ScanSkipReason
    std::size_t beams_bad_range = 0;  // beams marked invalid: NaN, +-inf, negative, huge range
    std::size_t odometry_bad = 0;     // scans whose odometry was not finite (used as unknown)
    double dropped_pct = 0.0;
    std::size_t points_in = 0, points_removed = 0;
    double prefilter_us_per_scan = 0.0;  // mean over input scans
    double icp_ms_per_scan = 0.0;        // map-builder time / input scans
    double icp_ms_per_kept_scan = 0.0;   // map-builder time / kept scans
    double cpu_s_total = 0.0;            // process CPU time of the run (I/O included)
    double wall_s_total = 0.0;
    Pipeline::Params pipeline;  // what ran
    std::optional<RelationsError> relations;
    std::optional<double> ate_rmse;  // m, against ground_truth_tum after SE(2) alignment
    std::string relations_file;
};

/// Everything a run produced, for the report (kfd/report/slam_report.h) and other callers.
struct IcpSlamResult {
    IcpSlamSummary summary;
    Trajectory trajectory;               // one pose per input scan (time order of the log)
    Trajectory odometry;                 // the odometry of every input scan that had one
    std::vector<std::size_t> keyframes;  // indices into `trajectory` of the kept scans
    Trajectory ground_truth;             // ground_truth_tum, sorted by time (empty without it)
    std::optional<mrpt::maps::CSimpleMap> map;  // the built map, with write_map
    /// The staged output folder holding what run() wrote; writeIcpSlamReport() adds the report
    /// and commits it (callers without a report call output->commit()). Removed uncommitted
    /// when the last copy of the result goes.
    std::shared_ptr<StagedOutputFolder> output;
};

/// Every file kfd-icp-slam may write into its output folder (checked against the inputs).
inline constexpr const char* kIcpSlamOutputFiles[] = {
    "trajectory.tum", "log_estimated_path.txt", "scans.csv", "summary.json", "final_map.simplemap",
    "map.png",        "map_figure.png",         "report.md"};

/// Bad input, configuration or output (message says which).
class SlamError : public Error {
  public:
    using Error::Error;
};

/// Runs CMetricMapBuilderICP over a rawlog exactly like MRPT's icp-slam (same config sections,
/// same call sequence), with the pre-filter deciding which scans reach scan matching. A dropped
/// scan in an actions+sensory-frames log is removed from its frame and the frame's odometry
/// action is still processed; in an observations log the scan is skipped and odometry
/// observations are still processed. Every input scan gets a pose (the map builder's estimate,
/// propagated with odometry for dropped scans). Every scan is checked by kfd::checkScan first,
/// in every mode (`none` included): a bad geometry skips it (counted, never reaches ICP), bad
/// ranges are marked invalid, and a non-finite odometry reading is left out of the map builder's
/// input. Relations given but none matched, or a negative relations_max_dt, are errors.
///
/// Checks first that the configuration, the rawlog, the relations and the ground truth are
/// readable (the ground truth and relations are parsed before the run) and that no output file
/// is (or aliases) one of them (PathError). Stops with kfd::Cancelled after
/// kfd::requestCancel(). Writes into a staging folder (kfd::StagedOutputFolder: beside a new
/// output folder, inside an existing one, whose other files are left alone), held by
/// IcpSlamResult::output: trajectory.tum (one pose per input scan, TUM format),
/// log_estimated_path.txt (icp-slam's "step x y phi", one per rawlog entry) and scans.csv.
/// summary.json, final_map.simplemap, map.png, map_figure.png and report.md are written from
/// the result by writeIcpSlamReport() (kfd/report/slam_report.h).
class IcpSlamRunner {
  public:
    IcpSlamResult run(const IcpSlamOptions& opts);
};

}  // namespace kfd
