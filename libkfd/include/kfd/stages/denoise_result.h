// What a denoising stage (denoise, range_aware_denoise, evidence_denoise) did to one scan: the
// diagnostics all three report, so that the per-scan records read one type (std only).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "kfd/paper/clusters.h"
#include "kfd/pipeline/scan.h"
#include "kfd/pipeline/stage.h"
#include "kfd/pipeline/stage_outputs.h"

namespace kfd {

/// Which denoising stage ran: the paper's Algorithm 2 (`denoise`), kfd's range-aware
/// clustering (`range_aware_denoise`) or kfd's evidence filter (`evidence_denoise`).
enum class DenoiseVariant : std::uint8_t { Reference, RangeAware, Evidence };
/// "reference", "range_aware", "evidence" (the values of the config key `variant`).
const char* toString(DenoiseVariant v);
/// The stage that runs variant v: "denoise", "range_aware_denoise", "evidence_denoise".
const char* stageName(DenoiseVariant v);

struct DenoiseResult {
    DenoiseVariant variant = DenoiseVariant::Reference;
    bool temporal = false;           // evidence: the previous keyframe was used
    std::size_t points_in = 0;       // valid beams before
    std::size_t clusters = 0;        // all clusters found
    std::size_t noise_clusters = 0;  // clusters removed
    std::size_t points_removed = 0;  // beams invalidated
    std::size_t blocks = 0;          // reference: blocks before merging
    std::size_t merges = 0;          // unions across rings / bridging points / seam
    double r_max = 0.0;              // m, reference: ring radius used
    double theta_threshold = 0.0;    // rad
    double sigma = 0.0;              // m, evidence: range noise used (EvidenceFilter)
    double sigma_measured = 0.0;     // m, evidence: the residuals' estimate before the floor
    std::size_t free_points = 0;     // evidence: returns the previous keyframe saw through
    bool stale_references = false;   // evidence: bound on removal ignored its references
    bool capped = false;             // evidence: removal cut to the bound
    bool confirmed = false;          // evidence: above the bound, confirmed by the scan before
    bool recent = false;             // evidence: the raw scan just before was used
    bool next = false;               // evidence: the raw scan just after was used
    std::size_t spikes = 0;          // evidence: spikes removed (step 4b)
    std::size_t veils = 0;           // evidence: mixed pixels removed (step 6)
    std::size_t surface_kept = 0;    // evidence: returns kept as a surface (step 7)
};

/// A denoising stage's start on a scan: the result's variant and points_in, and every valid
/// beam without a usable range (kfd::isUsableRange: NaN, +-inf, negative, above
/// kMaxScanRangeM) invalidated, counted in points_removed (such a beam has no place in a
/// cluster; normally the distance stage has removed it already).
DenoiseResult startDenoising(Scan& scan, DenoiseVariant variant);

/// Its end: the clusters counted, the removals reported as noise, `r` kept as the stage's
/// diagnostics. Returns true (a denoising stage never drops a scan).
bool endDenoising(const Clusters& c, DenoiseResult& r, StageReport& report);

/// The per-scan columns every denoising stage declares: clusters, noise_clusters.
std::vector<StageColumn> denoiseColumns();

}  // namespace kfd
