// kfd's scan tracker (issue 35) as a pipeline stage, named "track": put before the keyframe
// stage, so that the selector reads each scan's track and a dropped scan keeps its pose.
#pragma once

#include <vector>

#include "kfd/algorithms/scan_tracker.h"
#include "kfd/pipeline/stage.h"
#include "kfd/pipeline/stage_outputs.h"

namespace kfd {

/// Never drops a scan and never removes a point: aligns every scan to the last kept one
/// (ScanTracker) and learns which scans were kept from the chain's verdict (Stage::decided).
/// Diagnostics: TrackResult.
class TrackStage : public Stage {
  public:
    static constexpr const char* kName = "track";
    static constexpr const char* kHelp =
        "track every scan against the last keyframe (point-to-line alignment): each scan's "
        "pose, kept or dropped, and a verdict the keyframe stage listens to";
    using Params = ScanTracker::Params;
    /// Keys: track_samples, track_iterations, track_gate_m, track_min_gate_m,
    /// track_min_overlap, track_max_spread, track_min_conditioning, track_link_incidence_deg.
    static std::vector<StageKey> keys();
    /// Its per-scan CSV columns (kfd/pipeline/stage_outputs.h).
    static std::vector<StageColumn> columns();
    /// Its counters of a run (summaries, summary.json).
    static std::vector<StageCounter> counters();

    explicit TrackStage(const Params& p = {}) : algo_(p) {}
    const char* name() const override { return kName; }
    bool process(Scan& scan, StageReport& report, const ScanReport& chain) override;
    void decided(const Scan& scan, bool kept) override;
    void reset() override { algo_.reset(); }
    const ScanTracker& algorithm() const { return algo_; }

  private:
    ScanTracker algo_;
};

}  // namespace kfd
