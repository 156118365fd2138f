// The one per-scan CSV writer: kfd-filter's --stats file and kfd-icp-slam's scans.csv.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "kfd/mrpt/scan_record.h"
#include "kfd/os/output_paths.h"
#include "kfd/pipeline/error.h"
#include "kfd/pipeline/stage_outputs.h"

namespace kfd {

/// A per-scan CSV that cannot be written: the message names the file and the reason ("cannot
/// write s.csv: No space left on device"), `field()` the file.
class ScanCsvError : public Error {
  public:
    using Error::Error;
};

/// Writes ScanRecords as CSV rows, one per scan, under this header:
///
///     index,timestamp,sensor,kept,reason,points_in,removed_noise,surface_m,points_out,
///     microseconds,
///     <the listed stages' columns>,icp_goodness,odom_x,odom_y,odom_phi,x,y,phi
///
/// The door's columns: index, timestamp (s, 0 when unknown), sensor, kept (1/0) and reason as
/// in ScanRecord; points_in, removed_noise (by the denoising stages), points_out: valid beams;
/// surface_m: the longest run the denoisers removed that looks like a surface (m, 0: none);
/// microseconds: the pipeline's time. Then each listed stage's own columns, in pipeline
/// order, as the stage declares them (`kfd-filter --list-columns` prints them with their
/// meaning; kfd/pipeline/stage_outputs.h): e.g. removed_range (distance), p_common,
/// p_threshold, references (keyframe), view_change, changed_fraction, degeneracy, corridor
/// (view_keyframe), clusters, noise_clusters (the denoising stages), denoise_bound
/// (evidence_denoise), odometry_check (odometry_check). Then icp_goodness: kfd-icp-slam, ICP's
/// goodness when it corrected this scan's pose (0-1; "r" appended when the map builder
/// rejected the correction), else empty; odom_x, odom_y, odom_phi: the odometry the scan came
/// with (m, m, rad; empty when unknown or --laser-only); x, y, phi: the SLAM's pose of the
/// scan (kfd-icp-slam; empty in kfd-filter). A skipped scan's reason is "skipped:<why>", its
/// points_in its beam count, its stage cells those of a stage that did not run.
class ScanCsvWriter {
  public:
    /// Opens `path` for writing (kfd's checked OutputFile) and writes the header; `name` is the
    /// file users know (e.g. the final name of a temporary file). ScanCsvError when it cannot
    /// be written.
    /// `stages`: the door's outputs (StreamFilter::outputs()), which give the listed stages'
    /// columns and format each row's cells from its record's report.
    void open(const std::string& path, const std::string& name, const StageOutputs& stages);
    bool isOpen() const { return out_ && out_->isOpen(); }
    /// One row; `pose` fills x, y, phi. ScanCsvError when the write fails.
    void write(const ScanRecord& r, const std::optional<Pose2D>& pose = std::nullopt);
    /// Flushes, fsyncs, checks and closes (OutputFile::close); ScanCsvError when anything
    /// failed to be written.
    void close();

  private:
    std::optional<OutputFile> out_;
    StageOutputs stages_;
};

}  // namespace kfd
