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

const StageChoice::Option* StageChoice::find(std::string_view value) const {
    for (const auto& o : options)
        if (o.value == value) return &o;
    return nullptr;
}

const StageChoice::Option* StageChoice::ofStage(std::string_view stage) const {
    for (const auto& o : options)
        if (o.stage == stage) return &o;
    return nullptr;
}

const StageChoice::Option* StageChoice::listedIn(const std::vector<std::string>& stages) const {
    for (const auto& st : stages)
        if (const Option* o = ofStage(st)) return o;
    return nullptr;
}

std::string StageChoice::values() const {
    std::string s;
    for (const auto& o : options) s += (s.empty() ? "" : ", ") + o.value;
    return s;
}

void StageRegistry::addChoice(StageChoice c) {
    if (c.key.empty() || choice(c.key))
        throw Error("stage registry: choice key '" + c.key + "' empty or registered twice", c.key);
    for (const auto& o : c.options)
        if (!find(o.stage))
            throw Error(
                "stage registry: choice '" + c.key + "' names unknown stage '" + o.stage + "'",
                c.key);
    choices_.push_back(std::move(c));
}

const StageChoice* StageRegistry::choice(std::string_view key) const {
    for (const auto& c : choices_)
        if (c.key == key) return &c;
    return nullptr;
}

const StageChoice* StageRegistry::choiceOfStage(std::string_view stage) const {
    for (const auto& c : choices_)
        if (c.ofStage(stage)) return &c;
    return nullptr;
}

StageRegistry makeStageRegistry(std::initializer_list<void (*)(StageRegistry&)> registrars) {
    StageRegistry r;
    for (auto* add : registrars) add(r);
    return r;
}

}  // namespace kfd
