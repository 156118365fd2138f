#include "kfd/mrpt/config.h"

#include <mrpt/config/CConfigFile.h>
#include <mrpt/containers/yaml.h>
#include <mrpt/system/string_utils.h>

#include <cctype>
#include <filesystem>
#include <sstream>

#include "kfd/core/stage_keys.h"
#include "kfd/mrpt/default_stages.h"

namespace kfd {
namespace {

using mrpt::system::trim;

const StageKey* findKey(const StageRegistry& registry, const std::string& name,
                        const StageInfo** stage) {
    for (const auto& s : registry.stages())
        for (const auto& k : s.keys)
            if (k.name == name) {
                *stage = &s;
                return &k;
            }
    return nullptr;
}

std::string knownKeyList(const StageRegistry& registry) {
    std::string s;
    for (const auto& k : configKeys(registry)) s += (s.empty() ? "" : ", ") + k.name;
    return s;
}

std::vector<std::string> parseStageList(const std::string& text, const StageRegistry& registry) {
    std::vector<std::string> stages;
    std::stringstream ss(text);
    std::string item;
    while (std::getline(ss, item, ',')) {
        item = trim(item);
        if (item.empty()) continue;
        if (!registry.find(item))
            throw ConfigError("pipeline",
                              "unknown stage '" + item + "' (known: " + registry.names() + ")");
        for (const auto& s : stages)
            if (s == item) throw ConfigError("pipeline", "stage '" + item + "' repeated");
        stages.push_back(item);
    }
    return stages;
}

std::string scalarText(const mrpt::containers::yaml& node, const std::string& key) {
    if (node.isSequence()) {
        std::string s;
        for (const auto& item : node.asSequence()) {
            const mrpt::containers::yaml y(item);
            s += (s.empty() ? "" : ",") + scalarText(y, key);
        }
        return s;
    }
    if (!node.isScalar()) throw ConfigError(key, "expected a value or a list of values");
    try {
        return node.as<std::string>();
    } catch (const std::exception&) {
    }
    try {
        return keys::formatReal(node.as<double>());
    } catch (const std::exception&) {
    }
    try {
        return node.as<bool>() ? "1" : "0";
    } catch (const std::exception&) {
    }
    throw ConfigError(key, "cannot read the value");
}

}  // namespace

std::vector<ConfigKeyInfo> configKeys(const StageRegistry& registry) {
    std::vector<ConfigKeyInfo> v;
    v.push_back({"pipeline", "stages in order, comma separated", registry.names()});
    for (const auto& s : registry.stages())
        for (const auto& k : s.keys) v.push_back({k.name, k.help, k.range});
    return v;
}

const std::vector<ConfigKeyInfo>& configKeys() {
    static const std::vector<ConfigKeyInfo> infos = configKeys(defaultStageRegistry());
    return infos;
}

void applyConfigKey(Pipeline::Params& p, const std::string& key, const std::string& value,
                    const StageRegistry& registry) {
    if (key == "pipeline") {
        p.stages = parseStageList(value, registry);
        return;
    }
    const StageInfo* stage = nullptr;
    const StageKey* k = findKey(registry, key, &stage);
    if (!k) throw ConfigError(key, "unknown key (known keys: " + knownKeyList(registry) + ")");
    try {
        k->set(p.at(*stage).data(), trim(value));  // values reach the stages trimmed
    } catch (const ParameterError& e) {
        throw ConfigError(key, e.detail());
    }
}

void validateConfig(const Pipeline::Params& p, const StageRegistry& registry) {
    for (const auto& e : p.entries()) {
        const StageInfo* stage = registry.find(e.stage);
        if (!stage) continue;
        try {
            stage->validate(*e.params);
        } catch (const ParameterError& err) {
            const StageKey* k = stage->keyForField(err.field());
            throw ConfigError(k ? k->name : "", err.detail());
        }
    }
}

Pipeline::Params loadIni(const mrpt::config::CConfigFileBase& cfg, const std::string& section) {
    if (!cfg.sectionExists(section))
        throw ConfigError("", "no [" + section + "] section in the configuration");
    std::vector<std::string> names;
    cfg.getAllKeys(section, names);
    const StageRegistry& registry = defaultStageRegistry();
    Pipeline::Params p;
    for (const auto& name : names)
        applyConfigKey(p, name, cfg.read_string(section, name, ""), registry);
    validateConfig(p, registry);
    return p;
}

Pipeline::Params loadYaml(const mrpt::containers::yaml& doc) {
    if (!doc.isMap()) throw ConfigError("", "the YAML document must be a map of kfd keys");
    const mrpt::containers::yaml root = doc.has("kfd") ? doc["kfd"] : doc;
    if (!root.isMap()) throw ConfigError("kfd", "must be a map of kfd keys");
    const StageRegistry& registry = defaultStageRegistry();
    Pipeline::Params p;
    for (const auto& kv : root.asMap()) {
        const std::string name = std::string(kv.first.internalAsStr());
        applyConfigKey(p, name, scalarText(mrpt::containers::yaml(kv.second), name), registry);
    }
    validateConfig(p, registry);
    return p;
}

Pipeline::Params loadConfigFile(const std::string& path, const std::string& section) {
    namespace fs = std::filesystem;
    std::error_code ec;
    if (!fs::is_regular_file(path, ec))
        throw ConfigError("", "configuration file not found: " + path);
    std::string ext = fs::path(path).extension().string();
    for (auto& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (ext == ".yaml" || ext == ".yml") {
        mrpt::containers::yaml doc;
        try {
            doc = mrpt::containers::yaml::FromFile(path);
        } catch (const std::exception& e) {
            throw ConfigError("", "cannot parse YAML file " + path + ": " + e.what());
        }
        return loadYaml(doc);
    }
    if (ext != ".ini" && ext != ".cfg")
        throw ConfigError("", "unknown configuration format '" + ext + "' (use .ini or .yaml)");
    mrpt::config::CConfigFile cfg(path);
    return loadIni(cfg, section);
}

std::string toIni(const Pipeline::Params& p, const std::string& section) {
    std::string s = "[" + section + "]\n";
    std::string stages;
    for (const auto& st : p.stages) stages += (stages.empty() ? "" : ", ") + st;
    s += "pipeline = " + stages + "\n";
    for (const auto& stage : defaultStageRegistry().stages()) {
        const StageParams* set = p.find(stage.name);
        const auto defaults = set ? nullptr : stage.defaults();
        const void* params = set ? set->data() : defaults->data();
        for (const auto& k : stage.keys) s += k.name + " = " + k.get(params) + "\n";
    }
    return s;
}

}  // namespace kfd
