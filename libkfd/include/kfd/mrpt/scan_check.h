// Validation of one MRPT scan before it reaches any stage or MRPT's ICP (issue 9, item 2).
#pragma once

#include <mrpt/obs/CObservation2DRangeScan.h>

#include <cstddef>
#include <optional>

#include "kfd/pipeline/scan.h"

namespace kfd {

/// The check of the one door: StreamFilter::process (kfd/mrpt/stream_filter.h) runs it on every
/// scan before any stage, and nothing else does. Skip reasons are kfd::ScanSkipReason
/// (kfd/pipeline/scan.h). A skipped scan never reaches a stage nor the map builder; it is counted
/// per reason (ScanCounters, the per-scan CSV's reason "skipped:<reason>").

/// What checkScan() found.
struct ScanCheck {
    ScanSkipReason reject = ScanSkipReason::None;  // bad geometry: skip the whole scan
    std::size_t bad_ranges = 0;  // beams flagged valid whose range was NaN, +-inf, negative or
                                 // above kMaxScanRangeM: now marked invalid (the scan goes on)
    bool bad_odometry = false;   // the odometry had a non-finite component: now unknown
    bool ok() const { return reject == ScanSkipReason::None; }
};

/// The rule, applied to every scan read from a log:
///  - bad geometry rejects the scan (nothing is changed): beam count outside
///    [kMinScanBeams, kMaxScanBeams], aperture not finite, <= 0 or > 2*pi;
///  - a beam flagged valid whose range is NaN, +-inf, negative or above kMaxScanRangeM is marked
///    invalid in `obs` and counted (the scan goes on; its range value is left as it was);
///  - `odometry` with a non-finite x, y or phi is reset to unknown (std::nullopt) and counted.
/// MRPT's API keeps the range and validity buffers the same size, so that is not checked here
/// (the core checks it: Pipeline::process throws ScanError). Timestamps are not rejected: an
/// unset stamp is NaN (unknown) and a stamp that goes backwards is allowed (StreamFilter counts
/// it, StreamResult::stamp_backwards).
ScanCheck checkScan(mrpt::obs::CObservation2DRangeScan& obs,
                    std::optional<Pose2D>* odometry = nullptr);
/// The same, converting the scan into `core` on the way (kfd::toCore; the door's form: one
/// pass over the beams, buffers reused). `core` is left as it was when the scan is rejected.
ScanCheck checkScan(mrpt::obs::CObservation2DRangeScan& obs, std::optional<Pose2D>* odometry,
                    Scan& core);

/// The odometry rule of checkScan alone: a pose with a non-finite x, y or phi is reset to
/// unknown. Returns true when it was (for readers of odometry without a scan, such as
/// kfd-icp-slam's motion-filter pre-pass).
bool checkOdometry(std::optional<Pose2D>& odometry);

}  // namespace kfd
