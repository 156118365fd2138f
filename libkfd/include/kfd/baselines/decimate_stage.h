// Uniform decimation as a pipeline stage, named "decimate" (baseline, beyond the paper).
#pragma once

#include <vector>

#include "kfd/baselines/decimator.h"
#include "kfd/pipeline/stage.h"

namespace kfd {

/// Drops scans so that decimate_keep of them are kept, evenly by count; never changes a beam.
/// No diagnostics.
class DecimateStage : public Stage {
  public:
    static constexpr const char* kName = "decimate";
    static constexpr const char* kHelp =
        "baseline: keep a fixed share of the scans, evenly (uniform decimation)";
    using Params = Decimator::Params;
    /// Keys: decimate_keep.
    static std::vector<StageKey> keys();

    explicit DecimateStage(const Params& p = {}) : algo_(p) {}
    const char* name() const override { return kName; }
    bool process(Scan&, StageReport&, const ScanReport&) override { return algo_.keep(); }
    void reset() override { algo_.reset(); }
    const Decimator& algorithm() const { return algo_; }

  private:
    Decimator algo_;
};

}  // namespace kfd
