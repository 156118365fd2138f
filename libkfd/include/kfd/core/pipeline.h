// The per-scan filter chain (Figure 1 of the paper): distance filter -> keyframe -> denoise.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "kfd/core/dbscan.h"
#include "kfd/core/denoiser.h"
#include "kfd/core/distance_filter.h"
#include "kfd/core/keyframe_selector.h"
#include "kfd/core/motion_filter.h"
#include "kfd/core/radius_outlier.h"
#include "kfd/core/scan.h"
#include "kfd/core/statistical_outlier.h"

namespace kfd {

/// Everything the chain learned about one scan.
struct ScanReport {
    bool keep = true;                 // false: a stage dropped the scan
    std::string dropped_by;           // stage name that dropped it (empty when kept)
    bool keyframe_evaluated = false;  // the keyframe stage ran
    bool denoised = false;            // the denoise stage ran
    DistanceFilter::Result distance;
    KeyframeDecision keyframe;
    Denoiser::Result denoise;
    DbscanFilter::Result dbscan;           // when the dbscan stage ran
    RadiusOutlierFilter::Result radius;    // when the radius stage ran
    StatisticalOutlierFilter::Result sor;  // when the sor stage ran
    std::size_t points_in = 0;             // valid beams on input
    std::size_t points_out = 0;            // valid beams on output
    double microseconds = 0.0;             // wall time spent in the chain

    /// Points invalidated as noise by whichever denoising stages ran (denoise, dbscan, radius,
    /// sor); the distance stage's removals are not noise.
    std::size_t noiseRemoved() const {
        return denoise.points_removed + dbscan.points_removed + radius.points_removed +
               sor.points_removed;
    }
};

/// One stage of the chain, as in mp2p_icp's filter pipelines: configured once, then called for
/// every scan. filter() returns false to drop the scan (later stages then do not run).
class ScanFilter {
  public:
    virtual ~ScanFilter() = default;
    virtual const char* name() const = 0;
    virtual bool filter(Scan& scan, ScanReport& report) = 0;
    /// Forget all stream state (called when the sensor's geometry changes).
    virtual void reset() {}
};

/// Algorithm 1 as a stage. Never drops a scan; invalidates out-of-range beams.
class DistanceStage : public ScanFilter {
  public:
    void initialize(const DistanceFilter::Params& p) { algo_.initialize(p); }
    const char* name() const override { return "distance"; }
    bool filter(Scan& scan, ScanReport& report) override;

  private:
    DistanceFilter algo_;
};

/// Keyframe extraction (Sec. 3.1) as a stage. Drops non-keyframes.
class KeyframeStage : public ScanFilter {
  public:
    void initialize(const KeyframeSelector::Params& p) { algo_.initialize(p); }
    const char* name() const override { return "keyframe"; }
    bool filter(Scan& scan, ScanReport& report) override;
    void reset() override { algo_.reset(); }

  private:
    KeyframeSelector algo_;
};

/// Clustering denoise (Sec. 3.2) as a stage. Never drops a scan; invalidates noise points.
class DenoiseStage : public ScanFilter {
  public:
    void initialize(const Denoiser::Params& p) { algo_.initialize(p); }
    const char* name() const override { return "denoise"; }
    bool filter(Scan& scan, ScanReport& report) override;
    const Denoiser& denoiser() const { return algo_; }

  private:
    Denoiser algo_;
};

/// The odometry motion filter (baseline) as a stage. Drops scans taken before enough motion.
class MotionStage : public ScanFilter {
  public:
    void initialize(const MotionFilter::Params& p) { algo_.initialize(p); }
    const char* name() const override { return "motion"; }
    bool filter(Scan& scan, ScanReport& report) override;
    void reset() override { algo_.reset(); }

  private:
    MotionFilter algo_;
};

/// DBSCAN denoise (baseline) as a stage. Never drops a scan; invalidates noise points.
class DbscanStage : public ScanFilter {
  public:
    void initialize(const DbscanFilter::Params& p) { algo_.initialize(p); }
    const char* name() const override { return "dbscan"; }
    bool filter(Scan& scan, ScanReport& report) override;

  private:
    DbscanFilter algo_;
};

/// Radius outlier removal (baseline) as a stage. Never drops a scan; invalidates noise points.
class RadiusStage : public ScanFilter {
  public:
    void initialize(const RadiusOutlierFilter::Params& p) { algo_.initialize(p); }
    const char* name() const override { return "radius"; }
    bool filter(Scan& scan, ScanReport& report) override;

  private:
    RadiusOutlierFilter algo_;
};

/// Statistical outlier removal (baseline) as a stage. Never drops a scan; invalidates noise
/// points.
class SorStage : public ScanFilter {
  public:
    void initialize(const StatisticalOutlierFilter::Params& p) { algo_.initialize(p); }
    const char* name() const override { return "sor"; }
    bool filter(Scan& scan, ScanReport& report) override;

  private:
    StatisticalOutlierFilter algo_;
};

class Pipeline {
  public:
    struct Params {
        /// Stage names in order, each at most once. kfd's: "distance", "keyframe", "denoise";
        /// baselines: "motion" (odometry motion filter), "dbscan" (DBSCAN denoise), "radius"
        /// (radius outlier removal), "sor" (statistical outlier removal).
        std::vector<std::string> stages{"distance", "keyframe", "denoise"};
        DistanceFilter::Params distance;
        KeyframeSelector::Params keyframe;
        Denoiser::Params denoise;
        MotionFilter::Params motion;
        DbscanFilter::Params dbscan;
        RadiusOutlierFilter::Params radius;
        StatisticalOutlierFilter::Params sor;
    };

    Pipeline() { initialize(Params{}); }
    explicit Pipeline(const Params& p) { initialize(p); }
    /// Builds the stages. Throws std::invalid_argument on an unknown or repeated stage name or
    /// on invalid stage parameters.
    void initialize(const Params& p);
    const Params& params() const { return params_; }

    /// Appends a custom stage (e.g. a baseline denoiser).
    void add(std::unique_ptr<ScanFilter> stage);

    /// Runs the scan through every stage until one drops it. Modifies only valid flags.
    ScanReport process(Scan& scan);
    void reset();

    const std::vector<std::unique_ptr<ScanFilter>>& stages() const { return stages_; }
    /// The denoise stage's clusters of the last denoised scan, or nullptr without that stage.
    const Clusters* lastClusters() const;

  private:
    Params params_;
    std::vector<std::unique_ptr<ScanFilter>> stages_;
};

}  // namespace kfd
