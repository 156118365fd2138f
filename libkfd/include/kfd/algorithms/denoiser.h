// Clustering denoise of a keyframe (Algorithm 2 + cluster filter), in two selectable variants.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "kfd/algorithms/evidence_filter.h"
#include "kfd/algorithms/range_aware_clustering.h"
#include "kfd/paper/clusters.h"
#include "kfd/paper/ring_clustering.h"
#include "kfd/pipeline/error.h"
#include "kfd/pipeline/scan.h"

namespace kfd {

enum class DenoiseVariant : std::uint8_t {
    Reference,  // the paper's Algorithm 2 exactly as published (RingClustering + fixed m_threshold)
    RangeAware,  // kfd's first variant (RangeAwareClustering + range-adaptive threshold)
    Evidence,    // kfd's default: spatial + temporal evidence, thresholds from the scan
};
const char* toString(DenoiseVariant v);
/// Parses "reference", "range_aware" or "evidence"; throws kfd::ParameterError otherwise.
DenoiseVariant parseDenoiseVariant(const std::string& s);

class Denoiser {
  public:
    /// The parameters of the two clustering variants and of the cluster filter, nested (the
    /// config key angle_gap_factor sets both variants' factor).
    struct Params {
        /// kfd's evidence variant by default; Reference selects the paper's exact method.
        DenoiseVariant variant = DenoiseVariant::Evidence;
        /// Reference variant: t, r_max (Formulas 6-8), theta_threshold factor (Sec. 3.2.2),
        /// d_threshold (Formula 10).
        RingClustering::Params reference;
        /// Range-aware variant: theta_threshold factor, breakpoint lambda and sigma.
        RangeAwareClustering::Params range_aware;
        /// Evidence variant (kfd/algorithms/evidence_filter.h); min_object_size_m follows
        /// filter.min_object_size_m.
        EvidenceFilter::Params evidence;
        /// Sec. 3.2.4: m_threshold (both variants); min_object_size_m and min_points_floor
        /// (range-aware variant only: the reference variant always uses the fixed m_threshold).
        ClusterFilterParams filter{10, 0.10, 3};
    };

    struct Result {
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
        bool confirmed = false;  // evidence: above the bound, confirmed by the scan just before
        bool recent = false;     // evidence: the raw scan just before was used
        bool next = false;       // evidence: the raw scan just after was used
    };

    Denoiser() { initialize(Params{}); }
    explicit Denoiser(const Params& p) { initialize(p); }
    void initialize(const Params& p);  // kfd::ParameterError on bad values
    const Params& params() const { return params_; }

    /// Clusters the scan and clears the valid flag of every noise point.
    /// Valid beams without a usable range (kfd::isUsableRange: NaN, +-inf, negative, above
    /// kMaxScanRangeM = 1e4 m) are invalidated first and counted in points_removed.
    /// Bounds per scan of n <= kMaxScanBeams beams: O(n) memory (buffers reused); time a few
    /// passes over the beams plus union-find, each beam compared only with the clusters still
    /// open within the angle gap.
    Result filter(Scan& scan) { return filter(scan, nullptr); }
    /// The same with the sensor's next scan as evidence (the evidence variant's next_scan,
    /// EvidenceFilter step 3c); `next` = nullptr: without it. The other variants ignore it.
    Result filter(Scan& scan, const Scan* next);
    /// The evidence variant with next_scan and temporal on: a keyframe's filter() wants the
    /// next scan (kfd::Pipeline holds the keyframe until it comes: one scan of latency).
    bool wantsNextScan() const {
        return params_.variant == DenoiseVariant::Evidence && params_.evidence.next_scan &&
               params_.evidence.temporal;
    }
    /// A scan not filtered (dropped by the keyframe stage): the evidence variant keeps a copy
    /// as temporal evidence for the next keyframe (EvidenceFilter::observe); the others
    /// ignore it.
    void observe(const Scan& scan) {
        if (params_.variant == DenoiseVariant::Evidence) evidence_.observe(scan);
    }
    /// Forgets stream state (the evidence variant's previous keyframe and noise estimate).
    void reset() { evidence_.reset(); }

    /// Clusters of the last filtered scan (labels per beam, noise flags), e.g. for rendering.
    const Clusters& clusters() const { return clusters_; }

  private:
    Params params_;
    RingClustering reference_;
    RangeAwareClustering range_aware_;
    EvidenceFilter evidence_;
    ClusterFilterParams filter_;
    Clusters clusters_;
};

}  // namespace kfd
