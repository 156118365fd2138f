// The stage interface of the per-scan chain, its per-stage and per-scan reports, and the typed
// holder of a stage's parameters (std only).
#pragma once

#include <array>
#include <cstddef>
#include <functional>
#include <memory>
#include <new>
#include <string>
#include <string_view>
#include <type_traits>
#include <typeinfo>

#include "kfd/pipeline/scan.h"

namespace kfd {

struct Clusters;  // kfd/paper/clusters.h

/// What one stage did to one scan: its name, whether it dropped the scan, the valid beams it
/// invalidated, the time it took, and its typed diagnostics (e.g. KeyframeDecision,
/// DenoiseResult), stored by value so a report stays valid after later scans.
class StageReport {
  public:
    /// Room for a stage's diagnostics; larger types are rejected at compile time.
    static constexpr std::size_t kDiagnosticsBytes = 128;

    const char* name = "";           // the stage's name()
    bool dropped = false;            // this stage dropped the scan (later stages did not run)
    bool noise = false;              // points_removed are noise (a denoising stage)
    std::size_t points_removed = 0;  // valid beams this stage invalidated
    double microseconds = 0.0;       // wall time spent in this stage
    /// A denoising stage (noise): the longest straight run of returns it removed, when one
    /// looks like a surface (kfd/algorithms/surface_run.h; the pipeline measures it), else 0.
    std::size_t surface_beams = 0;
    double surface_m = 0.0;  // m, that run's length

    /// Stores the stage's diagnostics (a trivially copyable struct), replacing any before.
    template <class T>
    void setDiagnostics(const T& d) {
        static_assert(std::is_trivially_copyable_v<T> && std::is_trivially_destructible_v<T>,
                      "stage diagnostics must be plain structs");
        static_assert(sizeof(T) <= kDiagnosticsBytes && alignof(T) <= alignof(std::max_align_t),
                      "stage diagnostics too large: raise StageReport::kDiagnosticsBytes");
        new (data_) T(d);
        type_ = &typeid(T);
    }
    /// The diagnostics if they are of type T, else nullptr.
    template <class T>
    const T* diagnostics() const {
        return type_ && *type_ == typeid(T) ? std::launder(reinterpret_cast<const T*>(data_))
                                            : nullptr;
    }

  private:
    const std::type_info* type_ = nullptr;
    alignas(std::max_align_t) unsigned char data_[kDiagnosticsBytes];  // set with type_
};

/// Everything the chain learned about one scan: one StageReport per stage that ran, in order.
/// A plain value (fixed capacity, no allocation): copy it freely.
struct ScanReport {
    static constexpr std::size_t kMaxStages = 12;

    bool keep = true;  // false: a stage dropped the scan
    /// Kept, but held by a stage that needs the sensor's next scan (Stage::defers): that stage
    /// and the later ones have not run yet; Pipeline::finished() hands the scan back finished.
    bool pending = false;
    std::string dropped_by;      // name of the stage that dropped it (empty when kept)
    std::size_t points_in = 0;   // valid beams on input
    std::size_t points_out = 0;  // valid beams on output
    double microseconds = 0.0;   // wall time spent in the chain
    std::array<StageReport, kMaxStages> stage_reports;
    std::size_t stage_count = 0;  // stages that ran (the first stage_count of stage_reports)

    const StageReport* begin() const { return stage_reports.data(); }
    const StageReport* end() const { return stage_reports.data() + stage_count; }
    /// The report of the stage called `name`, or nullptr when it did not run.
    const StageReport* stage(std::string_view name) const {
        for (const auto& s : *this)
            if (name == s.name) return &s;
        return nullptr;
    }
    /// The diagnostics of type T of the first stage that ran and produced them, or nullptr:
    /// e.g. `report.find<KeyframeDecision>()`.
    template <class T>
    const T* find() const {
        for (const auto& s : *this)
            if (const T* d = s.diagnostics<T>()) return d;
        return nullptr;
    }
    /// Like find<T>(), but a copy, and T{} when no stage produced T.
    template <class T>
    T findOrDefault() const {
        const T* d = find<T>();
        return d ? *d : T{};
    }
    /// The longest run that looked like a surface among the denoising stages' removals (m; 0:
    /// none did; StageReport::surface_m).
    double surfaceRemoved() const {
        double m = 0.0;
        for (const auto& s : *this) m = s.surface_m > m ? s.surface_m : m;
        return m;
    }
    /// Points invalidated as noise by the denoising stages that ran (StageReport::noise); the
    /// distance stage's removals are not noise.
    std::size_t noiseRemoved() const {
        std::size_t n = 0;
        for (const auto& s : *this)
            if (s.noise) n += s.points_removed;
        return n;
    }
};

/// One stage of the chain, as in mp2p_icp's filter pipelines: configured once, then called for
/// every scan. process() fills `report` (its own entry) and returns false to drop the scan
/// (later stages then do not run); `chain` holds the reports of the stages that ran before it.
/// It must not allocate in steady state.
class Stage {
  public:
    virtual ~Stage() = default;
    virtual const char* name() const = 0;
    virtual bool process(Scan& scan, StageReport& report, const ScanReport& chain) = 0;
    /// A scan an earlier stage dropped (process() does not run for it): a stage that learns
    /// from every scan the sensor took (the denoiser's temporal evidence, issue 25) looks at it
    /// here. Called for every stage after the one that dropped it, in order; must be cheap
    /// (a dropped scan's whole cost is the point of dropping it) and not allocate in steady
    /// state. `chain`: the dropped scan's report so far (the diagnostics of the stages that ran
    /// on it, e.g. the tracker's pose). The default ignores it.
    virtual void observeDropped(const Scan& /*scan*/, const ScanReport& /*chain*/) {}
    /// The chain's verdict on a scan this stage's process() ran on: kept (no stage dropped it;
    /// a scan held by a later stage counts as kept) or dropped, called for every such stage in
    /// order once the chain has run, with the scan as the later stages left it. A stage that
    /// needs to know which scans became keyframes (the tracker) learns it here. The default
    /// ignores it.
    virtual void decided(const Scan& /*scan*/, bool /*kept*/) {}
    /// Forget all stream state (called when the sensor's geometry changes).
    virtual void reset() {}
    /// The geometry of a scan of geometry `in` after this stage: `in` for every stage that
    /// only marks beams invalid; a resampling stage (beam_count) changes the count. The
    /// door restarts the chain only when the geometry the stages see changes
    /// (Pipeline::outputGeometry).
    virtual ScanGeometry outputGeometry(const ScanGeometry& in) const { return in; }
    /// True: a scan reaching this stage is finished only once the sensor's next scan reached it
    /// too (one scan of latency; the evidence denoiser's next_scan, issue 25). The pipeline
    /// then holds a copy of the scan instead of calling process(), and calls finish() with the
    /// next scan when that reaches this stage (processed, or observed when an earlier stage
    /// dropped it), or with nullptr at the end of the stream (Pipeline::finish, reset). Must
    /// not change after construction.
    virtual bool defers() const { return false; }
    /// process() for a held scan; `next`: the sensor's next scan as this stage sees it (only
    /// read, during the call), or nullptr when there is none.
    virtual bool finish(Scan& scan, StageReport& report, const ScanReport& chain,
                        const Scan* /*next*/) {
        return process(scan, report, chain);
    }
    /// A clustering stage's clusters of the last scan it denoised (labels per beam, noise
    /// flags; e.g. for kfd-render), else nullptr.
    virtual const Clusters* clusters() const { return nullptr; }
};

/// A stage around a beam filter `Algo` (Params, and Result filter(Scan&) with a points_removed
/// field): never drops a scan, counts its removals (as noise when `noise`), and keeps the
/// algorithm's Result as the diagnostics. A concrete stage adds kName, kHelp, keys() and name().
template <class Algo>
class BeamFilterStage : public Stage {
  public:
    using Params = typename Algo::Params;
    BeamFilterStage(const Params& p, bool noise) : algo_(p), noise_(noise) {}
    bool process(Scan& scan, StageReport& report, const ScanReport&) override {
        const auto r = algo_.filter(scan);
        report.noise = noise_;
        report.points_removed = r.points_removed;
        report.setDiagnostics(r);
        return true;
    }
    const Algo& algorithm() const { return algo_; }

  protected:
    Algo& mutableAlgorithm() { return algo_; }

  private:
    Algo algo_;
    bool noise_;
};

/// A denoiser's stage: its removals are noise (the denoising scores and bounds count them).
template <class Algo>
class DenoisingStage : public BeamFilterStage<Algo> {
  public:
    explicit DenoisingStage(const typename Algo::Params& p) : BeamFilterStage<Algo>(p, true) {}
};

/// A stage's parameters behind a type-erased handle, so that one Pipeline::Params can hold the
/// parameters of every stage of a registry without naming their types.
class StageParams {
  public:
    virtual ~StageParams() = default;
    virtual std::unique_ptr<StageParams> clone() const = 0;
    virtual const std::type_info& type() const = 0;
    virtual void* data() = 0;
    virtual const void* data() const = 0;
};

/// The parameters of a stage whose Params type is P.
template <class P>
class StageParamsOf final : public StageParams {
  public:
    StageParamsOf() = default;
    explicit StageParamsOf(const P& v) : value(v) {}
    std::unique_ptr<StageParams> clone() const override {
        return std::make_unique<StageParamsOf>(value);
    }
    const std::type_info& type() const override { return typeid(P); }
    void* data() override { return &value; }
    const void* data() const override { return &value; }
    P value;
};

/// One configuration key of a stage: the user's flat key (e.g. "window"), the Params field it
/// sets (e.g. "window", what ParameterError::field() names), help text with unit and formula,
/// and the allowed values. set() parses text and range-checks it (kfd::ParameterError naming
/// `field`); get() prints the current value so that set(get()) reads it back.
struct StageKey {
    std::string name;
    std::string field;
    std::string help;
    std::string range;
    std::function<void(void* params, const std::string& text)> set;
    std::function<std::string(const void* params)> get;
};

}  // namespace kfd
