// The one per-scan CSV writer: kfd-filter's --stats file and kfd-icp-slam's scans.csv.
#pragma once

#include <optional>
#include <string>

#include "kfd/mrpt/scan_record.h"
#include "kfd/os/output_paths.h"
#include "kfd/pipeline/error.h"

namespace kfd {

/// A per-scan CSV that cannot be written: the message names the file and the reason ("cannot
/// write s.csv: No space left on device"), `field()` the file.
class ScanCsvError : public Error {
  public:
    using Error::Error;
};

/// Writes ScanRecords as CSV rows, one per scan, under this header (the one column set):
///
///     index,timestamp,sensor,kept,reason,p_common,p_threshold,references,points_in,
///     removed_range,clusters,noise_clusters,removed_noise,points_out,microseconds,
///     view_change,changed_fraction,degeneracy,corridor,denoise_bound,odometry_check,icp_goodness,odom_x,odom_y,odom_phi,
///     x,y,phi
///
/// index, timestamp (s, 0 when unknown), sensor, kept (1/0) and reason as in ScanRecord;
/// p_common, p_threshold, references: the keyframe stage's Formula 3 values (0 without it);
/// points_in, removed_range, clusters, noise_clusters, removed_noise, points_out: beams and
/// clusters; microseconds: the pipeline's time; view_change, changed_fraction, degeneracy,
/// corridor (1/0): the view selector and corridor switch; denoise_bound: "none", or how the
/// evidence denoiser's bound on removal acted ("stale_references": temporal evidence ignored,
/// "capped": cut to the bound, "confirmed": above it, confirmed by the scan just before and
/// removed whole); odometry_check: "none" (no odometry or no check), "ok",
/// "frozen" or "jump" (kfd/algorithms/odometry_check.h: withheld from the stages); icp_goodness:
/// kfd-icp-slam, ICP's goodness when it corrected this scan's pose (0-1; "r" appended when the
/// map builder rejected the correction), else empty; odom_x, odom_y, odom_phi: the odometry
/// the scan came with (m, m, rad; empty when unknown or --laser-only); x, y, phi: the SLAM's pose
/// of the scan (kfd-icp-slam; empty in kfd-filter). A skipped scan's reason is
/// "skipped:<why>", its points_in its beam count, its other numbers 0 and degeneracy 1.
class ScanCsvWriter {
  public:
    /// Opens `path` for writing (kfd's checked OutputFile) and writes the header; `name` is the
    /// file users know (e.g. the final name of a temporary file). ScanCsvError when it cannot
    /// be written.
    void open(const std::string& path, const std::string& name);
    bool isOpen() const { return out_ && out_->isOpen(); }
    /// One row; `pose` fills x, y, phi. ScanCsvError when the write fails.
    void write(const ScanRecord& r, const std::optional<Pose2D>& pose = std::nullopt);
    /// Flushes, fsyncs, checks and closes (OutputFile::close); ScanCsvError when anything
    /// failed to be written.
    void close();

  private:
    std::optional<OutputFile> out_;
};

}  // namespace kfd
