// The per-scan filter chain (Figure 1 of the paper): distance filter -> keyframe -> denoise, as a
// list of stages found by name in a StageRegistry (std only).
#pragma once

#include <chrono>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "kfd/paper/clusters.h"
#include "kfd/pipeline/error.h"
#include "kfd/pipeline/scan.h"
#include "kfd/pipeline/stage.h"
#include "kfd/pipeline/stage_registry.h"

namespace kfd {

/// The stage list and every configured stage's parameters, typed:
///
///     kfd::Pipeline::Params p;
///     p.stages = {"distance", "keyframe", "denoise"};  // the paper's three stages
///     p.get<kfd::KeyframeStage>().window = 3;  // S::Params of stage class S
///
/// Stages whose parameters were never set run with their Params defaults.
class PipelineParams {
  public:
    /// Stage names in order (see StageRegistry::names()); a stage listed twice runs twice, its
    /// second instance called `<stage>_2` (instanceNames()), with parameters of its own. By
    /// default the
    /// distance filter and kfd's keyframe and denoising stages (kfdDefaults() adds the
    /// odometry check).
    std::vector<std::string> stages{"distance", "view_keyframe", "evidence_denoise"};

    /// Whether `stages` lists `stage` (once or more).
    bool lists(std::string_view stage) const;

    PipelineParams() = default;
    PipelineParams(const PipelineParams& o);
    PipelineParams& operator=(const PipelineParams& o);
    PipelineParams(PipelineParams&&) = default;
    PipelineParams& operator=(PipelineParams&&) = default;

    /// The parameters of stage class S (created with defaults when missing).
    template <class S>
    typename S::Params& get() {
        using P = typename S::Params;
        if (StageParams* p = find(S::kName)) {
            StageRegistry::paramsOf<P>(*p, S::kName);  // type check
            return *static_cast<P*>(p->data());
        }
        auto holder = std::make_unique<StageParamsOf<P>>();
        P& ref = holder->value;
        entries_.push_back(Entry{S::kName, std::move(holder)});
        return ref;
    }
    /// The parameters of stage class S (its defaults when never set).
    template <class S>
    const typename S::Params& get() const {
        using P = typename S::Params;
        if (const StageParams* p = find(S::kName)) return StageRegistry::paramsOf<P>(*p, S::kName);
        static const P defaults{};
        return defaults;
    }

    /// The parameters of a registered stage by name (created with its defaults when missing).
    StageParams& at(const StageInfo& stage);
    /// The parameters of one instance of `stage` ("denoise_2": its second listing).
    StageParams& at(const StageInfo& stage, std::string_view instance);
    /// The parameters set for stage `name`, or nullptr.
    StageParams* find(std::string_view name);
    const StageParams* find(std::string_view name) const;

    struct Entry {
        std::string stage;
        std::unique_ptr<StageParams> params;
    };
    /// The stages whose parameters were set, in the order they were first set.
    const std::vector<Entry>& entries() const { return entries_; }

  private:
    std::vector<Entry> entries_;
};

/// The instance name of each listed stage: the stage's name, `<stage>_<n>` for its n-th
/// listing: {"denoise", "distance", "denoise"} -> {"denoise", "distance", "denoise_2"}.
std::vector<std::string> instanceNames(const std::vector<std::string>& stages);

class Pipeline {
  public:
    using Params = PipelineParams;

    Pipeline() : Pipeline(Params{}) {}
    /// Builds the stages listed in p.stages from `registry` (the core stages by default; the
    /// MRPT layer's kfd::defaultStageRegistry() adds the baselines).
    /// The registry must outlive the pipeline (the built-in ones are static).
    explicit Pipeline(const Params& p, const StageRegistry& registry = coreStageRegistry()) {
        initialize(p, registry);
    }
    /// Builds the stages. Throws kfd::ParameterError (field "stages") on an unknown or repeated
    /// stage name, and the stage's kfd::ParameterError on invalid stage parameters. Parameters
    /// of registered stages that are set but not listed are validated too, so that a bad value
    /// is reported even while its stage is switched off. A held scan (see process()) is
    /// finished by the old stages first, without a next scan (finished() returns it).
    void initialize(const Params& p, const StageRegistry& registry);
    /// Rebuilds from the registry given at construction.
    void initialize(const Params& p) { initialize(p, *registry_); }
    const StageRegistry& registry() const { return *registry_; }
    const Params& params() const { return params_; }

    /// Appends a custom stage (kfd::Error on nullptr or beyond ScanReport::kMaxStages).
    void add(std::unique_ptr<Stage> stage);

    /// Runs the scan through every stage until one drops it. Modifies only valid flags.
    /// kfd::ScanError when the scan's range and valid sizes differ or its geometry is outside
    /// the limits of kfd/pipeline/scan.h (checkGeometry: 2..65 536 beams, aperture finite, > 0 and
    /// <= 2*pi); nothing is changed then. Any range is safe: every stage treats a beam flagged
    /// valid whose range is NaN, infinite or negative as unusable (the distance stage removes
    /// and counts it; the others skip it or mark it invalid), so no scan content is UB.
    ///
    /// One scan of latency (a stage that defers, e.g. the denoise stage with next_scan): a scan
    /// reaching that stage comes back with report.pending (kept; that stage and the later ones
    /// have not run, `scan` is as the earlier ones left it). The pipeline holds a copy; the next
    /// process() call finishes it with the new scan as evidence (before the new scan reaches
    /// that stage) and finished() then returns it. finish() ends a stream: the held scan is
    /// finished without a next scan. At most one scan is held.
    ScanReport process(Scan& scan);
    /// The scan held before and finished by the last process(), finish() or reset() call (the
    /// pipeline's copy, its valid flags final), its report in `report` (pending = false); else
    /// nullptr. Valid until the next call of one of them.
    const Scan* finished(ScanReport& report) const;
    /// Finishes the held scan without a next scan (the end of a log); false when none was held.
    bool finish();
    /// A scan is held (the last process() returned pending and nothing finished it yet).
    bool holding() const { return held_; }
    /// Forgets all stream state; a held scan is finished first (finished() returns it).
    void reset();
    /// The geometry the stages after all resampling see for an input scan of geometry `in`
    /// (Stage::outputGeometry through the chain): what a caller compares to decide that the
    /// sensor's geometry changed and the chain must restart (reset()).
    ScanGeometry outputGeometry(const ScanGeometry& in) const;

    const std::vector<std::unique_ptr<Stage>>& stages() const { return stages_; }
    /// The first stage of class S, or nullptr.
    template <class S>
    const S* find() const {
        for (const auto& s : stages_)
            if (const auto* t = dynamic_cast<const S*>(s.get())) return t;
        return nullptr;
    }
    /// The clusters of the last scan the first clustering stage denoised (Stage::clusters()),
    /// or nullptr without such a stage.
    const Clusters* lastClusters() const;

  private:
    Params params_;
    const StageRegistry* registry_ = &coreStageRegistry();
    std::vector<std::unique_ptr<Stage>> stages_;
    // One scan of latency (Stage::defers): the held copy, the stage holding it and its report.
    // Returns the time it took (not the new scan's).
    std::chrono::steady_clock::duration finishHeld(const Scan* next);
    bool held_ = false, finished_ = false;
    std::size_t held_stage_ = 0;
    Scan held_scan_, finished_scan_;
    std::vector<std::uint8_t> before_;  // a stage's input valid flags (surface check)
    ScanReport held_report_, finished_report_;
};

}  // namespace kfd
