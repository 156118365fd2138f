// Stages found by name (as mp2p_icp's class_name registry): what a pipeline, the config layer,
// --list-keys and kfd-icp-slam's modes know about every stage (std only).
#pragma once

#include <functional>
#include <initializer_list>
#include <memory>
#include <string>
#include <string_view>
#include <type_traits>
#include <typeinfo>
#include <vector>

#include "kfd/pipeline/error.h"
#include "kfd/pipeline/stage.h"
#include "kfd/pipeline/stage_outputs.h"

namespace kfd {

namespace detail {
template <class S, class = void>
struct DeclaresColumns : std::false_type {};
template <class S>
struct DeclaresColumns<S, std::void_t<decltype(S::columns())>> : std::true_type {};
template <class S, class = void>
struct DeclaresCounters : std::false_type {};
template <class S>
struct DeclaresCounters<S, std::void_t<decltype(S::counters())>> : std::true_type {};
}  // namespace detail

/// Everything the registry knows about one stage.
struct StageInfo {
    std::string name;                    // e.g. "keyframe", as listed in Pipeline::Params::stages
    std::string help;                    // one line
    std::vector<StageKey> keys;          // its configuration keys, in documentation order
    std::vector<StageColumn> columns;    // its per-scan CSV columns (kfd/pipeline/stage_outputs.h)
    std::vector<StageCounter> counters;  // its counters of a run
    std::function<std::unique_ptr<StageParams>()> defaults;  // its Params, default values
    /// Validates parameters of this stage (kfd::ParameterError naming the Params field).
    std::function<void(const StageParams&)> validate;
    /// Builds the stage (validating the parameters once, in the algorithm's initialize()).
    std::function<std::unique_ptr<Stage>(const StageParams&)> create;

    /// The key whose Params field is `field` (or whose name is `field`), or nullptr.
    const StageKey* keyForField(std::string_view field) const;
};

/// A flat key that chooses which of several stages of one role the pipeline runs, e.g.
/// `selector` (paper -> keyframe, view -> view_keyframe) and `variant` (the denoising stages):
/// setting it replaces the listed stage of that role by the chosen one (no effect when the
/// pipeline lists none).
struct StageChoice {
    std::string key;   // e.g. "selector"
    std::string help;  // one line
    struct Option {
        std::string value;  // e.g. "paper"
        std::string stage;  // e.g. "keyframe"
    };
    std::vector<Option> options;

    /// The stage chosen by `value`, or nullptr.
    const Option* find(std::string_view value) const;
    /// The option that runs stage `stage`, or nullptr.
    const Option* ofStage(std::string_view stage) const;
    /// The option of the first stage of this role that `stages` lists, or nullptr.
    const Option* listedIn(const std::vector<std::string>& stages) const;
    /// "paper, view".
    std::string values() const;
};

/// A set of stages by name. Registration is explicit (registerCoreStages(),
/// registerBaselineStages(), kfd::defaultStageRegistry() in the MRPT layer): static
/// initialisers in a static library would be dropped by the linker.
class StageRegistry {
  public:
    /// Registers stage class S, which provides: static constexpr const char* kName, kHelp;
    /// a copyable `Params` struct; static std::vector<StageKey> keys(); and a constructor
    /// S(const Params&) that throws kfd::ParameterError on invalid parameters; optionally its
    /// outputs: static std::vector<StageColumn> columns() and std::vector<StageCounter>
    /// counters().
    template <class S>
    void add() {
        using P = typename S::Params;
        StageInfo info;
        info.name = S::kName;
        info.help = S::kHelp;
        info.keys = S::keys();
        if constexpr (detail::DeclaresColumns<S>::value) info.columns = S::columns();
        if constexpr (detail::DeclaresCounters<S>::value) info.counters = S::counters();
        info.defaults = [] { return std::make_unique<StageParamsOf<P>>(); };
        info.validate = [](const StageParams& p) { S check(paramsOf<P>(p, S::kName)); };
        info.create = [](const StageParams& p) -> std::unique_ptr<Stage> {
            return std::make_unique<S>(paramsOf<P>(p, S::kName));
        };
        add(std::move(info));
    }
    /// Registers a stage; kfd::Error when the name is taken or empty.
    void add(StageInfo info);

    /// The stage called `name`, or nullptr.
    const StageInfo* find(std::string_view name) const;
    /// Every stage, in registration order.
    const std::vector<StageInfo>& stages() const { return stages_; }
    /// "distance, keyframe, denoise, ..." (registration order).
    std::string names() const;

    /// Registers a choice key (kfd::Error when its key is taken or an option names a stage
    /// not registered).
    void addChoice(StageChoice choice);
    /// Every choice key, in registration order.
    const std::vector<StageChoice>& choices() const { return choices_; }
    /// The choice whose key is `key`, or nullptr.
    const StageChoice* choice(std::string_view key) const;
    /// The choice one of whose options runs stage `stage` (the stage's role), or nullptr.
    const StageChoice* choiceOfStage(std::string_view stage) const;

    /// The typed Params inside `p`; kfd::Error when `p` holds another type.
    template <class P>
    static const P& paramsOf(const StageParams& p, const char* stage) {
        if (p.type() != typeid(P))
            throw Error(std::string("stage '") + stage + "': parameters of the wrong type", stage);
        return *static_cast<const P*>(p.data());
    }

  private:
    std::vector<StageInfo> stages_;
    std::vector<StageChoice> choices_;
};

/// A registry filled by `registrars` in order, e.g. {registerCoreStages, registerBaselineStages}.
StageRegistry makeStageRegistry(std::initializer_list<void (*)(StageRegistry&)> registrars);

/// Registers the core stages: the paper's distance (Algorithm 1), keyframe (Sec. 3.1) and
/// denoise (Sec. 3.2), kfd's view_keyframe, range_aware_denoise, evidence_denoise,
/// odometry_check and fuse, and the choice keys `selector` and `variant`.
void registerCoreStages(StageRegistry& registry);

/// A registry holding the core stages only (what Pipeline uses unless told otherwise).
const StageRegistry& coreStageRegistry();

}  // namespace kfd
