#include "kfd/slam/prefilter_modes.h"

#include "kfd/mrpt/default_stages.h"
#include "kfd/pipeline/error.h"

namespace kfd {
namespace {

// A mode that runs `stages`; described by the last stage's registry help unless told.
PrefilterModeInfo mode(PrefilterMode m, const char* name, std::vector<std::string> stages,
                       std::string description = {}) {
    const StageRegistry& reg = defaultStageRegistry();
    for (const auto& s : stages)
        if (!reg.find(s))
            throw Error("pre-filter mode '" + std::string(name) + "': no stage '" + s + "'", s);
    if (description.empty()) description = reg.find(stages.back())->help + " (after distance)";
    return PrefilterModeInfo{m, name, std::move(stages), false, std::move(description)};
}

std::vector<PrefilterModeInfo> buildModes() {
    std::vector<PrefilterModeInfo> v;
    v.push_back(mode(PrefilterMode::None, "none", {}, "no pre-filter: plain ICP-SLAM"));
    v.push_back(mode(PrefilterMode::Odometry, "odometry", {"motion"},
                     defaultStageRegistry().find("motion")->help));
    v.push_back(mode(PrefilterMode::Keyframe, "keyframe", {"distance", "track", "view_keyframe"},
                     "keyframe extraction only (distance + the [KFD] pipeline's keyframe "
                     "stage)"));
    PrefilterModeInfo kfd =
        mode(PrefilterMode::Kfd, "kfd",
             {"odometry_check", "distance", "track", "view_keyframe", "evidence_denoise"},
             "the full method: the [KFD] section's pipeline (default "
             "odometry_check, distance, track, view_keyframe, evidence_denoise)");
    kfd.uses_kfd_stages = true;
    v.push_back(kfd);
    v.push_back(mode(PrefilterMode::Dbscan, "dbscan", {"distance", "dbscan"}));
    v.push_back(mode(PrefilterMode::Radius, "radius", {"distance", "radius"}));
    v.push_back(mode(PrefilterMode::Sor, "sor", {"distance", "sor"}));
    v.push_back(mode(PrefilterMode::Decimate, "decimate", {"decimate"},
                     defaultStageRegistry().find("decimate")->help));
    return v;
}

}  // namespace

const std::vector<PrefilterModeInfo>& prefilterModes() {
    static const std::vector<PrefilterModeInfo> modes = buildModes();
    return modes;
}

const char* toString(PrefilterMode m) {
    for (const auto& info : prefilterModes())
        if (info.mode == m) return info.name.c_str();
    return "unknown";
}

PrefilterMode parsePrefilterMode(const std::string& s) {
    std::string names;
    for (const auto& info : prefilterModes()) {
        if (s == info.name) return info.mode;
        names += (names.empty() ? "" : ", ") + info.name;
    }
    throw ParameterError("mode", "unknown pre-filter mode '" + s + "' (expected " + names + ")");
}

Pipeline::Params pipelineForMode(PrefilterMode mode, const Pipeline::Params& kfd) {
    Pipeline::Params p = kfd;
    const StageRegistry& reg = defaultStageRegistry();
    for (const auto& info : prefilterModes()) {
        if (info.mode != mode || info.uses_kfd_stages) continue;
        p.stages = info.stages;
        // A stage with a role (selector, variant): the one the [KFD] pipeline chose, if any
        // (the first it lists, as everywhere: StageChoice::listedIn).
        for (auto& st : p.stages)
            if (const StageChoice* c = reg.choiceOfStage(st))
                if (const StageChoice::Option* o = c->listedIn(kfd.stages)) st = o->stage;
    }
    return p;
}

}  // namespace kfd
