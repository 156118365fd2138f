// What the one door for a scan (StreamFilter::process) says about each scan and about a run:
// one per-scan record and one set of counters, shared by every driver (kfd-filter, kfd-icp-slam
// and its pre-pass, kfd-render, the simulator's tools).
#pragma once

#include <cstddef>
#include <limits>
#include <optional>
#include <string>

#include "kfd/algorithms/odometry_check.h"
#include "kfd/pipeline/scan.h"

namespace kfd {

/// How the evidence denoiser's bound on removal acted on a scan (EvidenceFilter step 5).
enum class DenoiseBound {
    None,             // removed what the evidence said (within the bound)
    StaleReferences,  // the references disagreed with too much of the scan: spatial only
    Capped,           // even so above the bound: the smallest segments only
    Confirmed,        // above the bound, but the raw scan just before confirmed it: all removed
};
/// "none", "stale_references", "capped", "confirmed".
inline const char* toString(DenoiseBound b) {
    return b == DenoiseBound::Capped            ? "capped"
           : b == DenoiseBound::StaleReferences ? "stale_references"
           : b == DenoiseBound::Confirmed       ? "confirmed"
                                                : "none";
}

/// One scan as the door saw it: the row of the per-scan CSV (kfd/io/scan_csv.h documents
/// the columns). A skipped scan (bad geometry) has `skipped` set, points_in = its beam count
/// and zeros elsewhere.
struct ScanRecord {
    std::size_t index = 0;  // 0-based, every scan given to the door (skipped ones included)
    double stamp = 0.0;     // s; 0 when the scan has no stamp (kfd::stampForOutput)
    std::string sensor;     // the scan's sensor label
    bool kept = false;      // a keyframe: the scan goes on (to the output, to ICP)
    ScanSkipReason skipped = ScanSkipReason::None;  // not None: bad geometry, never ran
    const char* reason = "";  // keyframe reason ("view_change", "similar", ...), else "kept"
                              // or the stage that dropped it, or "skipped:<why>" (static text)
    double p_common = 0.0;    // the keyframe stage's P_common (Formula 3); 0 without it
    double p_threshold = 0.0;
    std::size_t references = 0;
    std::size_t points_in = 0;      // valid beams entering the pipeline
    std::size_t removed_range = 0;  // by Algorithm 1 (non-finite or outside the range limits)
    std::size_t clusters = 0;       // the denoiser's clusters (0 when it did not run)
    std::size_t noise_clusters = 0;
    std::size_t removed_noise = 0;  // by the denoising stages
    std::size_t points_out = 0;     // valid beams leaving the pipeline
    double microseconds = 0.0;      // time in the pipeline's stages
    double view_change = 0.0;       // the view selector's measures (kfd/algorithms/view_selector.h)
    double changed_fraction = 0.0;
    double degeneracy = 1.0;
    bool corridor = false;           // the corridor switch found the scan degenerate
    bool corridor_keyframe = false;  // ... and made it a keyframe by odometry or time
    DenoiseBound denoise_bound = DenoiseBound::None;         // the evidence denoiser's bound acted
    OdometryVerdict odometry_check = OdometryVerdict::None;  // the odometry check's verdict
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
    std::size_t beams_bad_range = 0;     // beams marked invalid: NaN, +-inf, negative, huge range
    std::size_t odometry_bad = 0;        // scans whose odometry was not finite (used as unknown)
    std::size_t stamps_backwards = 0;    // scans stamped before their sensor's previous scan
    std::size_t geometry_resets = 0;     // a sensor's geometry changed: its state was reset
    std::size_t scans_corridor = 0;      // scans the corridor switch found degenerate
    std::size_t keyframes_corridor = 0;  // keyframes the switch made (odometry or time)
    std::size_t scans_odometry_frozen = 0;  // scans whose odometry stood still as they changed
    std::size_t scans_odometry_jump = 0;    // scans whose odometry jumped where they did not
    std::size_t scans_denoise_stale = 0;    // kept scans whose denoiser found its references stale
    std::size_t scans_denoise_capped = 0;   // kept scans whose removal was cut to the bound
    std::size_t scans_denoise_confirmed = 0;  // kept scans above the bound, confirmed (all removed)
    /// The largest share of a kept scan's valid returns the denoising stages removed (0-1).
    double max_removed_noise_share = 0.0;
    std::size_t points_in = 0;             // valid beams of the scans that ran
    std::size_t points_removed_range = 0;  // by Algorithm 1, in kept scans
    std::size_t points_removed_noise = 0;  // by the denoising stages, in kept scans
    std::size_t points_removed = 0;        // points_in - points_out over the kept scans
    double filter_seconds = 0.0;           // time inside the pipeline's stages

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
