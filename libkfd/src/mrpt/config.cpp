#include "kfd/mrpt/config.h"

#include <mrpt/config/CConfigFile.h>
#include <mrpt/containers/yaml.h>
#include <mrpt/system/string_utils.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include "kfd/mrpt/default_stages.h"
#include "kfd/pipeline/stage_keys.h"
#include "yaml_check.h"

namespace kfd {
namespace {

using mrpt::system::trim;

// Every stage of `registry` that declares key `name` (a flat key sets it in each: e.g.
// m_threshold in denoise and range_aware_denoise, the guards in both keyframe stages).
std::vector<std::pair<const StageInfo*, const StageKey*>> findKey(const StageRegistry& registry,
                                                                  const std::string& name) {
    std::vector<std::pair<const StageInfo*, const StageKey*>> found;
    for (const auto& s : registry.stages())
        for (const auto& k : s.keys)
            if (k.name == name) found.emplace_back(&s, &k);
    return found;
}

// Each key name once, in registration order: "pipeline", the choice keys, then every stage's.
std::vector<std::string> keyNames(const StageRegistry& registry) {
    std::vector<std::string> names{"pipeline"};
    for (const auto& c : registry.choices()) names.push_back(c.key);
    for (const auto& st : registry.stages())
        for (const auto& k : st.keys)
            if (std::find(names.begin(), names.end(), k.name) == names.end())
                names.push_back(k.name);
    return names;
}

std::string knownKeyList(const StageRegistry& registry) {
    std::string s;  // configKeys()'s order, without its values
    for (const auto& n : keyNames(registry)) s += (s.empty() ? "" : ", ") + n;
    return s;
}

// A choice key: the listed stage of its role replaced by the chosen one.
void applyChoice(Pipeline::Params& p, const StageChoice& c, const std::string& value) {
    const StageChoice::Option* chosen = c.find(value);
    if (!chosen)
        throw ConfigError(c.key, "unknown " + c.key + " '" + value + "' (" + c.values() + ")");
    for (auto& st : p.stages)
        if (c.ofStage(st)) st = chosen->stage;
    for (std::size_t i = 0; i < p.stages.size(); ++i)  // listed twice now: keep the first
        for (std::size_t j = i + 1; j < p.stages.size(); ++j)
            if (p.stages[j] == p.stages[i]) p.stages.erase(p.stages.begin() + j--);
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
        stages.push_back(item);
    }
    if (stages.empty())
        throw ConfigError("pipeline", "no stage listed (known: " + registry.names() + ")");
    return stages;
}

std::string lower(std::string s) {
    for (auto& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

std::string readWholeFile(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    if (!f) throw ConfigError("", "cannot read configuration file " + path);
    std::ostringstream ss;
    ss << f.rdbuf();
    return ss.str();
}

// The text of `cfg` when it was read from a file (CConfigFile); empty otherwise
// (CConfigFileMemory keeps only the parsed keys, duplicates already merged).
std::optional<std::string> iniTextOf(const mrpt::config::CConfigFileBase& cfg) {
    if (const auto* f = dynamic_cast<const mrpt::config::CConfigFile*>(&cfg))
        return readWholeFile(f->getAssociatedFile());
    return std::nullopt;
}

// MRPT's exception banner as its message (kfd::plainMessage), on one line.
std::string mrptMessage(const std::string& what) {
    const std::string m = plainMessage(what);
    return m.substr(0, m.find('\n'));
}

}  // namespace

void checkIniText(const std::string& text, const std::string& section) {
    // MRPT's CConfigFile keeps the last of two equal keys (compared without case): find them
    // in the text first. Sections compare without case too, as in MRPT.
    std::map<std::string, std::size_t> seen;  // lower-case key -> line
    bool in_section = false;
    const auto lines = detail::splitLines(text);
    for (std::size_t n = 0; n < lines.size(); ++n) {
        const std::string line = trim(lines[n]);
        if (line.empty() || line[0] == ';' || line[0] == '#') continue;
        if (line[0] == '[') {
            const auto close = line.find(']');
            in_section = close != std::string::npos &&
                         lower(trim(line.substr(1, close - 1))) == lower(section);
            continue;
        }
        if (!in_section) continue;
        const auto eq = line.find('=');
        if (eq == std::string::npos) continue;
        const std::string key = trim(line.substr(0, eq));
        const auto [it, inserted] = seen.emplace(lower(key), n + 1);
        if (!inserted)
            throw ConfigError(key, "set twice in [" + section + "] (lines " +
                                       std::to_string(it->second) + " and " +
                                       std::to_string(n + 1) + ")");
    }
}

void checkYamlText(const std::string& text) { detail::checkYaml(text); }

Pipeline::Params loadYamlText(const std::string& text, const std::string& origin,
                              const Pipeline::Params* base, std::vector<std::string>* notes) {
    checkYamlText(text);
    mrpt::containers::yaml doc;
    try {
        doc = mrpt::containers::yaml::FromText(text);
    } catch (const std::exception& e) {
        throw ConfigError("", "cannot parse YAML " + origin + ": " + e.what());
    }
    return loadYaml(doc, base, notes);
}

namespace {

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

namespace {

std::string stageList(const Pipeline::Params& p, const char* sep) {
    std::string s;
    for (const auto& st : p.stages) s += (s.empty() ? "" : sep) + st;
    return s;
}

// The value of choice `c` in `p`: the option of the stage of its role that `p` lists ("" when
// none is listed).
std::string choiceValue(const Pipeline::Params& p, const StageChoice& c) {
    const auto* o = c.listedIn(p.stages);
    return o ? o->value : "";
}

// The value of key `name` in `p`: from the first stage declaring it that `p` lists, else the
// first declaring it; the stage's parameters set in `p`, else its defaults.
std::string keyValue(const Pipeline::Params& p, const StageRegistry& registry,
                     const std::string& name) {
    const auto found = findKey(registry, name);
    auto from = found.front();
    for (const auto& f : found)
        if (p.lists(f.first->name)) {
            from = f;
            break;
        }
    if (const StageParams* set = p.find(from.first->name)) return from.second->get(set->data());
    return from.second->get(from.first->defaults()->data());
}

}  // namespace

std::vector<ConfigKeyInfo> configKeys(const StageRegistry& registry) {
    const Pipeline::Params plain, kfd = kfdDefaults();
    std::vector<ConfigKeyInfo> v;
    v.push_back({"pipeline", "stages in order, comma separated", registry.names(),
                 stageList(plain, ","), stageList(kfd, ",")});
    for (const auto& c : registry.choices())
        v.push_back({c.key, c.help, c.values(), choiceValue(plain, c), choiceValue(kfd, c)});
    for (const auto& name : keyNames(registry)) {
        const auto found = findKey(registry, name);
        if (found.empty()) continue;  // pipeline and the choices, above
        std::string help = found.front().second->help;
        if (found.size() > 1) {
            help += " (stages:";
            for (const auto& f : found) help += " " + f.first->name;
            help += ")";
        }
        v.push_back({name, help, found.front().second->range, keyValue(plain, registry, name),
                     keyValue(kfd, registry, name)});
    }
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
    if (const StageChoice* c = registry.choice(key)) {
        applyChoice(p, *c, trim(value));
        return;
    }
    const auto found = findKey(registry, key);
    if (found.empty())
        throw ConfigError(key, "unknown key (known keys: " + knownKeyList(registry) + ")");
    try {
        for (const auto& [stage, k] : found)
            k->set(p.at(*stage).data(), trim(value));  // values reach the stages trimmed
    } catch (const ParameterError& e) {
        throw ConfigError(key, e.detail());
    }
}

void applyConfigKeys(Pipeline::Params& p,
                     const std::vector<std::pair<std::string, std::string>>& values,
                     const StageRegistry& registry) {
    // "pipeline" first, then the choice keys (which edit its list), then the stages' keys.
    auto rank = [&registry](const std::string& key) {
        return key == "pipeline" ? 0 : registry.choice(key) ? 1 : 2;
    };
    for (int r = 0; r < 3; ++r)
        for (const auto& [key, value] : values)
            if (rank(key) == r) applyConfigKey(p, key, value, registry);
}

namespace {

// The registered stage of instance `name` ("denoise", "denoise_2"), or nullptr.
const StageInfo* stageOfInstance(const StageRegistry& registry, const std::string& name) {
    if (const StageInfo* info = registry.find(name)) return info;
    const auto cut = name.find_last_of('_');
    if (cut == std::string::npos || cut + 1 == name.size() ||
        name.find_first_not_of("0123456789", cut + 1) != std::string::npos)
        return nullptr;
    return registry.find(name.substr(0, cut));
}

// The flat stage keys of `keys` (not pipeline, not a choice key), in their order.
std::vector<std::string> flatStageKeys(const ConfigValues& values, const StageRegistry& registry) {
    std::vector<std::string> flat;
    for (const auto& kv : values.keys)
        if (kv.first != "pipeline" && !registry.choice(kv.first)) flat.push_back(kv.first);
    return flat;
}

// The note on flat keys: read for this release, each with its new spelling (the listed stages
// that declare it), or the remark that no listed stage does.
std::string flatKeysNote(const std::vector<std::string>& flat, const Pipeline::Params& p,
                         const StageRegistry& registry, const ConfigSyntax& syntax) {
    std::map<std::string, std::string> by_stage;  // instance -> its keys
    std::vector<std::string> order;
    std::string unused;
    for (const std::string& key : flat) {
        bool listed = false;
        for (const auto& [stage, k] : findKey(registry, key))
            if (p.lists(stage->name)) {
                if (!by_stage.count(stage->name)) order.push_back(stage->name);
                std::string& keys = by_stage[stage->name];
                keys += (keys.empty() ? "" : ", ") + key;
                listed = true;
            }
        if (!listed) unused += (unused.empty() ? "" : ", ") + key;
    }
    std::string note = plural(flat.size(), "flat key") + " in " + syntax.flatPlace() +
                       ", read for this release: write them per stage, ";
    for (std::size_t i = 0; i < order.size(); ++i)
        note += (i ? "; " : "") + syntax.spell(order[i], by_stage[order[i]]);
    if (!unused.empty())
        note += std::string(order.empty() ? "" : "; ") + unused +
                ": no stage of the pipeline has them (they set stages it does not run)";
    return note;
}

// One stage instance's keys: ConfigError naming both when the instance is not in the
// pipeline, naming the key when the stage has no such key.
void applySection(Pipeline::Params& p, const ConfigValues::Section& section,
                  const StageRegistry& registry, const ConfigSyntax& syntax) {
    const std::vector<std::string> instances = instanceNames(p.stages);
    const auto it = std::find(instances.begin(), instances.end(), section.stage);
    const std::string where = syntax.sectionName(section.stage);
    if (it == instances.end()) {
        const StageInfo* info = stageOfInstance(registry, section.stage);
        throw ConfigError(section.stage,
                          where + ": " +
                              (info ? "stage '" + section.stage + "' is not in the pipeline ("
                                    : "no stage '" + section.stage +
                                          "' (known: " + registry.names() + "; the pipeline: ") +
                              stageList(p, ", ") + ")");
    }
    const StageInfo& info =
        *registry.find(p.stages[static_cast<std::size_t>(it - instances.begin())]);
    for (const auto& [key, value] : section.keys) {
        const StageKey* k = nullptr;
        for (const auto& candidate : info.keys)
            if (candidate.name == key) k = &candidate;
        if (!k) {
            std::string known;
            for (const auto& candidate : info.keys)
                known += (known.empty() ? "" : ", ") + candidate.name;
            throw ConfigError(
                key, where + ": not a key of stage " + info.name + " (its keys: " + known + ")");
        }
        try {
            k->set(p.at(info, section.stage).data(), trim(value));
        } catch (const ParameterError& e) {
            throw ConfigError(key, where + ": " + e.detail());
        }
    }
}

}  // namespace

std::string ConfigSyntax::sectionName(const std::string& stage) const {
    if (kind == Yaml) return "kfd: " + stage + ":";
    if (kind == RosParams) return "~" + stage + "/";
    if (kind == Ros2Params) return stage + ".";
    return "[" + section + "." + stage + "]";
}

std::string ConfigSyntax::flatPlace() const {
    if (kind == Yaml) return "the kfd: map";
    if (kind == RosParams) return "the node's private parameters";
    if (kind == Ros2Params) return "the node's parameters";
    return "[" + section + "]";
}

std::string ConfigSyntax::spell(const std::string& stage, const std::string& keys) const {
    if (kind == Yaml) return "kfd: " + stage + ": {" + keys + "}";
    if (kind == RosParams) return "~" + stage + "/{" + keys + "}";
    if (kind == Ros2Params) return stage + ".{" + keys + "}";
    return sectionName(stage) + " " + keys;
}

void applyConfig(Pipeline::Params& p, const ConfigValues& values, const StageRegistry& registry,
                 const ConfigSyntax& syntax, std::vector<std::string>* notes) {
    applyConfigKeys(p, values.keys, registry);
    for (const auto& section : values.sections) applySection(p, section, registry, syntax);
    const std::vector<std::string> flat = flatStageKeys(values, registry);
    if (notes && !flat.empty()) notes->push_back(flatKeysNote(flat, p, registry, syntax));
}

void validateConfig(const Pipeline::Params& p, const StageRegistry& registry) {
    for (const auto& e : p.entries()) {
        const StageInfo* stage = stageOfInstance(registry, e.stage);
        if (!stage) continue;
        try {
            stage->validate(*e.params);
        } catch (const ParameterError& err) {
            const StageKey* k = stage->keyForField(err.field());
            throw ConfigError(k ? k->name : "", err.detail());
        }
    }
}

namespace {

// The keys of one .ini section, as (key, value).
std::vector<std::pair<std::string, std::string>> iniKeys(const mrpt::config::CConfigFileBase& cfg,
                                                         const std::string& section) {
    std::vector<std::pair<std::string, std::string>> values;
    try {
        std::vector<std::string> names;
        cfg.getAllKeys(section, names);
        for (const auto& name : names)
            values.emplace_back(name, cfg.read_string(section, name, ""));
    } catch (const std::exception& e) {
        throw ConfigError("", "cannot read [" + section + "]: " + mrptMessage(e.what()));
    }
    return values;
}

// [section] and its stages' sections [section.<stage>], as read.
ConfigValues iniValues(const mrpt::config::CConfigFileBase& cfg, const std::string& section) {
    ConfigValues v;
    v.keys = iniKeys(cfg, section);
    std::vector<std::string> sections;
    cfg.getAllSections(sections);
    const std::string prefix = lower(section) + ".";
    for (const std::string& name : sections)
        if (lower(name).rfind(prefix, 0) == 0)
            v.sections.push_back({lower(name.substr(prefix.size())), iniKeys(cfg, name)});
    return v;
}

}  // namespace

Pipeline::Params loadIni(const mrpt::config::CConfigFileBase& cfg, const std::string& section,
                         const Pipeline::Params* base, std::vector<std::string>* notes) {
    if (!cfg.sectionExists(section))
        throw ConfigError("", "no [" + section + "] section in the configuration");
    const ConfigValues values = iniValues(cfg, section);
    if (const auto text = iniTextOf(cfg)) {
        checkIniText(*text, section);
        for (const auto& s : values.sections) checkIniText(*text, section + "." + s.stage);
    }
    const StageRegistry& registry = defaultStageRegistry();
    Pipeline::Params p = base ? *base : kfdDefaults();
    applyConfig(p, values, registry, ConfigSyntax{ConfigSyntax::Ini, section}, notes);
    validateConfig(p, registry);
    return p;
}

Pipeline::Params loadYaml(const mrpt::containers::yaml& doc, const Pipeline::Params* base,
                          std::vector<std::string>* notes) {
    if (!doc.isMap()) throw ConfigError("", "the YAML document must be a map of kfd keys");
    const mrpt::containers::yaml root = doc.has("kfd") ? doc["kfd"] : doc;
    if (!root.isMap()) throw ConfigError("kfd", "must be a map of kfd keys");
    if (doc.has("kfd"))  // a key beside kfd: would be silently ignored
        for (const auto& kv : doc.asMap())
            if (const std::string name(kv.first.internalAsStr()); name != "kfd")
                throw ConfigError(name,
                                  "beside the top-level kfd: map, which holds every kfd "
                                  "key: move it under kfd:");
    const StageRegistry& registry = defaultStageRegistry();
    Pipeline::Params p = base ? *base : kfdDefaults();
    ConfigValues values;
    for (const auto& kv : root.asMap()) {
        const std::string name = std::string(kv.first.internalAsStr());
        const mrpt::containers::yaml node(kv.second);
        if (!node.isMap()) {
            values.keys.emplace_back(name, scalarText(node, name));
            continue;
        }
        ConfigValues::Section section{name, {}};  // a stage's map: its keys
        for (const auto& skv : node.asMap()) {
            const std::string key = std::string(skv.first.internalAsStr());
            section.keys.emplace_back(key, scalarText(mrpt::containers::yaml(skv.second), key));
        }
        values.sections.push_back(std::move(section));
    }
    applyConfig(p, values, registry, ConfigSyntax{ConfigSyntax::Yaml, "kfd"}, notes);
    validateConfig(p, registry);
    return p;
}

namespace {

// What MRPT's readers would silently cut or turn into a bare "==== MRPT exception ====": a
// NUL byte (the C string ends there: "3<NUL>junk" read as 3), and in an .ini a ${NAME} no
// @define before it names.
void checkConfigBytes(const std::string& text, const std::string& path, bool ini) {
    std::set<std::string> defined;
    const auto lines = detail::splitLines(text);
    for (std::size_t n = 0; n < lines.size(); ++n) {
        const std::string& line = lines[n];
        const std::string where = path + " line " + std::to_string(n + 1);
        if (line.find('\0') != std::string::npos)
            throw ConfigError("", where + " holds a NUL byte: not a text file");
        if (!ini) continue;
        const std::string t = trim(line);
        if (t.rfind("@define", 0) == 0) {
            std::istringstream s(t.substr(7));
            std::string name;
            if (s >> name) defined.insert(name);
            continue;
        }
        for (auto at = line.find("${"); at != std::string::npos; at = line.find("${", at + 2)) {
            const auto close = line.find('}', at);
            const std::string name = line.substr(
                at + 2, close == std::string::npos ? std::string::npos : close - at - 2);
            if (close == std::string::npos || !defined.count(name))
                throw ConfigError("", where + ": ${" + name +
                                          "} is not defined (an .ini defines it with '@define " +
                                          name + " VALUE' on a line before; $env{" + name +
                                          "} reads the environment)");
        }
    }
}

}  // namespace

Pipeline::Params loadConfigFile(const std::string& path, const std::string& section,
                                std::vector<std::string>* notes) {
    namespace fs = std::filesystem;
    std::error_code ec;
    if (!fs::is_regular_file(path, ec))
        throw ConfigError("", "configuration file not found: " + path);
    std::string ext = fs::path(path).extension().string();
    for (auto& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (ext == ".yaml" || ext == ".yml") {
        std::error_code size_ec;
        const auto bytes = fs::file_size(path, size_ec);
        if (!size_ec && bytes > kMaxConfigBytes)
            throw ConfigError("", "YAML file " + path + " larger than " +
                                      std::to_string(kMaxConfigBytes) + " bytes");
        const std::string text = readWholeFile(path);
        checkConfigBytes(text, path, false);
        try {
            checkYamlText(text);
        } catch (const ConfigError& e) {
            if (!e.key().empty()) throw;
            throw ConfigError("", path + ": " + e.what());
        }
        return loadYamlText(text, "file " + path, nullptr, notes);
    }
    if (ext != ".ini" && ext != ".cfg")
        throw ConfigError("", "unknown configuration format '" + ext + "' (use .ini or .yaml)");
    // MRPT's CConfigFile expands @define, ${var}, $env{} and $eval{} while reading and throws
    // its own exceptions for malformed ones (found by test/fuzz/fuzz_ini).
    checkConfigBytes(readWholeFile(path), path, true);
    std::optional<mrpt::config::CConfigFile> cfg;
    try {
        cfg.emplace(path);
    } catch (const std::exception& e) {
        throw ConfigError("", "cannot read .ini file " + path + ": " + mrptMessage(e.what()));
    }
    return loadIni(*cfg, section, nullptr, notes);
}

std::string toIni(const Pipeline::Params& p, const std::string& section) {
    const StageRegistry& registry = defaultStageRegistry();
    std::string s = "[" + section + "]\npipeline = " + stageList(p, ", ") + "\n";
    const std::vector<std::string> instances = instanceNames(p.stages);
    for (std::size_t i = 0; i < instances.size(); ++i) {
        const StageInfo* info = registry.find(p.stages[i]);
        if (!info) continue;
        s += "\n[" + section + "." + instances[i] + "]\n";
        const StageParams* set = p.find(instances[i]);
        const auto defaults = info->defaults();
        for (const StageKey& k : info->keys)
            s += k.name + " = " + k.get(set ? set->data() : defaults->data()) + "\n";
    }
    return s;
}

}  // namespace kfd
