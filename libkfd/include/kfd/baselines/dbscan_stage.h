// DBSCAN denoise as a pipeline stage, named "dbscan" (baseline, beyond the paper).
#pragma once

#include <vector>

#include "kfd/baselines/dbscan.h"
#include "kfd/pipeline/stage.h"

namespace kfd {

/// Never drops a scan; invalidates noise points. Diagnostics: DbscanFilter::Result.
class DbscanStage : public DenoisingStage<DbscanFilter> {
  public:
    static constexpr const char* kName = "dbscan";
    static constexpr const char* kHelp =
        "baseline: DBSCAN denoise (Ester et al. 1996; the paper's comparison, Sec. 4)";
    /// Keys: dbscan_eps_m, dbscan_min_pts.
    static std::vector<StageKey> keys();

    explicit DbscanStage(const Params& p = {}) : DenoisingStage(p) {}
    const char* name() const override { return kName; }
};

}  // namespace kfd
