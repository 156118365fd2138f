// A fixed beam count (issue 37): every scan resampled to the same number of beams over its own
// aperture, as the stage "beam_count", for a driver whose count varies from revolution to
// revolution (slam_toolbox rejects such scans; kfd's stages would restart at every change).
// std only.
#pragma once

#include <cstddef>
#include <vector>

#include "kfd/pipeline/scan.h"
#include "kfd/pipeline/stage.h"
#include "kfd/pipeline/stage_keys.h"
#include "kfd/pipeline/stage_outputs.h"

namespace kfd {

/// Resamples a scan of n beams to `beams` beams spanning the same aperture in the same
/// direction: output beam j lies at input position u = j (n - 1) / (beams - 1). Between input
/// beams i and i + 1 (both valid, ranges within max_jump of the nearer one: one surface) the
/// range and intensity are interpolated linearly; otherwise output beam j takes the nearer
/// input beam as it is, invalid included, so no point is made up between a near and a far
/// surface (no mixed pixel) and a gap stays a gap. A scan that already has `beams` beams is
/// left untouched. Time O(n + beams); no allocation once the buffers have grown.
class BeamCountResampler {
  public:
    struct Params {
        std::size_t beams = 0;   // beams out; 0: the first scan's count (learned by the stage)
        double max_jump = 0.05;  // neighbours interpolated when |r0 - r1| <= max_jump * min(r0, r1)
    };
    struct Result {
        std::size_t beams_in = 0;        // the driver's beam count
        std::size_t beams_out = 0;       // the count after resampling
        std::size_t points_in = 0;       // valid beams on input
        std::size_t points_out = 0;      // valid beams on output
        std::size_t points_removed = 0;  // max(0, points_in - points_out)
        std::size_t resampled = 0;       // 1 when the count changed
    };

    BeamCountResampler() = default;
    explicit BeamCountResampler(const Params& p) { initialize(p); }
    /// kfd::ParameterError unless beams is 0 or in [kMinScanBeams, kMaxScanBeams] and
    /// 0 <= max_jump <= 1.
    void initialize(const Params& p);
    const Params& params() const { return params_; }
    /// Resamples `scan` to `beams` beams (>= kMinScanBeams); `buffer` is scratch space (its
    /// old contents are swapped into it).
    Result resample(Scan& scan, std::size_t beams, Scan& buffer) const;

  private:
    Params params_;
};

class BeamCountStage : public Stage {
  public:
    using Params = BeamCountResampler::Params;
    static constexpr const char* kName = "beam_count";
    static constexpr const char* kHelp =
        "resamples every scan to a fixed beam count over its aperture (a driver whose count "
        "varies; the first scan's count by default)";
    /// Keys: beam_count, beam_count_max_jump.
    static std::vector<StageKey> keys();
    static std::vector<StageColumn> columns();
    static std::vector<StageCounter> counters();

    explicit BeamCountStage(const Params& p = {}) : algo_(p) {}
    const char* name() const override { return kName; }
    bool process(Scan& scan, StageReport& report, const ScanReport& chain) override;
    /// The geometry the later stages see: `in` with the fixed count (once known), so a driver
    /// whose count varies does not restart them.
    ScanGeometry outputGeometry(const ScanGeometry& in) const override;
    /// Keeps the learned count: it describes the output stream, which a restart continues.
    void reset() override {}
    const BeamCountResampler& algorithm() const { return algo_; }

  private:
    BeamCountResampler algo_;
    std::size_t target_ = 0;  // the count out (params' or the first scan's); 0 until known
    Scan buffer_;
};

}  // namespace kfd
