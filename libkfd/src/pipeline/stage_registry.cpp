#include "kfd/pipeline/stage_registry.h"

namespace kfd {

const StageKey* StageInfo::keyForField(std::string_view field) const {
    for (const auto& k : keys)
        if (k.field == field) return &k;
    for (const auto& k : keys)
        if (k.name == field) return &k;
    return nullptr;
}

void StageRegistry::add(StageInfo info) {
    if (info.name.empty()) throw Error("stage registry: a stage needs a name");
    if (find(info.name))
        throw Error("stage registry: stage '" + info.name + "' registered twice", info.name);
    stages_.push_back(std::move(info));
}

const StageInfo* StageRegistry::find(std::string_view name) const {
    for (const auto& s : stages_)
        if (s.name == name) return &s;
    return nullptr;
}

std::string StageRegistry::names() const {
    std::string s;
    for (const auto& st : stages_) s += (s.empty() ? "" : ", ") + st.name;
    return s;
}

StageRegistry makeStageRegistry(std::initializer_list<void (*)(StageRegistry&)> registrars) {
    StageRegistry r;
    for (auto* add : registrars) add(r);
    return r;
}

}  // namespace kfd
