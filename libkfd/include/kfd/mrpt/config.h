// Configuration of the kfd pipeline from an MRPT-style .ini section or from YAML.
#pragma once

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "kfd/pipeline/error.h"
#include "kfd/pipeline/pipeline.h"
#include "kfd/pipeline/stage_registry.h"

namespace mrpt::config {
class CConfigFileBase;
}
namespace mrpt::containers {
class yaml;
}

namespace kfd {

/// A configuration problem. `key()` (= field()) names the offending key (empty for file-level
/// problems).
class ConfigError : public Error {
  public:
    ConfigError(const std::string& key, const std::string& message)
        : Error(key.empty() ? message : "config key '" + key + "': " + message, key) {}
    const std::string& key() const { return field(); }
};

/// One recognised key: name, meaning (with unit), the allowed values and its two defaults.
struct ConfigKeyInfo {
    std::string name;
    std::string help;
    std::string range;
    /// The stage's own default (Pipeline::Params{}): what a C++ caller building its
    /// parameters in code starts from.
    std::string default_value;
    /// kfd's default (kfdDefaults(), share/kfd/default.ini): the value without any
    /// configuration (kfd-filter without -c, kfd-icp-slam without [KFD]) and the value of a key
    /// a configuration file leaves out (the loaders read a file over kfdDefaults()).
    std::string kfd_value;
};
/// Every key the loaders accept, in documentation order: "pipeline", then the keys of every
/// stage of `registry` in registration order (derived from the stages' own key lists), each
/// with its values in Pipeline::Params{} and in kfdDefaults() (a stage's values as its key
/// printers write them, e.g. "0.01", "scan").
std::vector<ConfigKeyInfo> configKeys(const StageRegistry& registry);
/// configKeys(defaultStageRegistry()).
const std::vector<ConfigKeyInfo>& configKeys();

/// Sets one key (e.g. "window" = "3") in `p`: "pipeline" takes a comma-separated stage list;
/// a choice key of `registry` (`selector`, `variant`) replaces the listed stage of its role by
/// the one chosen; every other key sets that key of every stage of `registry` that declares it
/// (e.g. m_threshold: denoise and range_aware_denoise). ConfigError naming the key on an
/// unknown key or a bad value.
void applyConfigKey(Pipeline::Params& p, const std::string& key, const std::string& value,
                    const StageRegistry& registry);
/// applyConfigKey for each (key, value): "pipeline" first, then the choice keys, then the
/// stages' keys, so that the file's order does not matter.
void applyConfigKeys(Pipeline::Params& p,
                     const std::vector<std::pair<std::string, std::string>>& values,
                     const StageRegistry& registry);
/// A configuration as read, before it is applied: the top section's keys ([KFD] or the kfd:
/// map: `pipeline`, the choice keys, and flat stage keys, read for this release), then each
/// stage's own keys ([KFD.<stage>], `kfd: <stage>: {...}`, the ROS node's `~<stage>/<key>`).
/// A stage listed twice is configured as `<stage>_2` (kfd::instanceNames).
struct ConfigValues {
    std::vector<std::pair<std::string, std::string>> keys;
    struct Section {
        std::string stage;  // the instance: "distance", "denoise_2"
        std::vector<std::pair<std::string, std::string>> keys;
    };
    std::vector<Section> sections;
};

/// How the user wrote the configuration, for messages: the sections' and keys' spelling.
struct ConfigSyntax {
    // RosParams: the ROS 1 node's ~<stage>/<key>; Ros2Params: the ROS 2 node's <stage>.<key>.
    enum Kind { Ini, Yaml, RosParams, Ros2Params } kind = Ini;
    std::string section = "KFD";  // the .ini section (Ini)
    /// "[KFD.distance]", "kfd: distance:", "~distance/", "distance.".
    std::string sectionName(const std::string& stage) const;
    /// "[KFD]", "the kfd: map", "the node's private parameters", "the node's parameters".
    std::string flatPlace() const;
    /// "[KFD.distance] min_range, max_range" and the like.
    std::string spell(const std::string& stage, const std::string& keys) const;
};

/// Applies `values` to `p`: the top keys (applyConfigKeys), then each stage's section. A
/// section of a stage the pipeline does not list is a ConfigError naming the stage and the
/// pipeline; a key the stage does not declare one naming the key and the stage's keys. Flat
/// stage keys (the spelling before issue 34) still set every stage declaring them; when
/// `notes` is given, one note there names each with its new spelling.
void applyConfig(Pipeline::Params& p, const ConfigValues& values, const StageRegistry& registry,
                 const ConfigSyntax& syntax, std::vector<std::string>* notes = nullptr);

/// Validates every stage's parameters set in `p` once (each stage's own checks); ConfigError
/// naming the user's key for the stage's kfd::ParameterError.
void validateConfig(const Pipeline::Params& p, const StageRegistry& registry);

/// Reads the keys of `section` (default "KFD") over `base`: kfd's defaults (kfdDefaults(),
/// share/kfd/default.ini) when null, so that a file setting one key changes only that key of
/// what runs without a file (kfdDefaults() itself reads over Pipeline::Params{}). When
/// `cfg` is a CConfigFile its file's text is checked first (checkIniText; a
/// CConfigFileMemory has already merged duplicate keys: check its text with checkIniText).
/// Unknown keys and out-of-range values throw ConfigError naming the key. Other sections are
/// ignored, so the [KFD] section can live inside an icp-slam .ini.
///
/// Each stage's keys live in a section of its own, [KFD.<stage>] (applyConfig); [KFD] holds
/// `pipeline`, the choice keys (`selector`, `variant`) and, for this release, the flat keys of
/// before (a note in `notes` gives their new spelling).
Pipeline::Params loadIni(const mrpt::config::CConfigFileBase& cfg,
                         const std::string& section = "KFD", const Pipeline::Params* base = nullptr,
                         std::vector<std::string>* notes = nullptr);

/// Largest configuration text the YAML loader reads (1 MiB); kfd's keys need a few hundred
/// bytes.
constexpr std::size_t kMaxConfigBytes = std::size_t{1} << 20;
/// Deepest YAML nesting the loader reads: `kfd:`, a stage, its keys.
constexpr std::size_t kMaxYamlLevels = 3;

/// Checks the text of an .ini file before MRPT reads it (MRPT keeps the last of two equal
/// keys silently): ConfigError naming the key when a key of `section` appears twice (keys and
/// sections compared without case, as MRPT does).
void checkIniText(const std::string& text, const std::string& section = "KFD");

/// Checks YAML text before it reaches MRPT's YAML parser (libfyaml, which can loop forever on
/// malformed text, e.g. the 4 bytes "%\xff\xff\n"), so that no file can hang a tool.
/// ConfigError (file level, or naming the key) unless:
///  - size: at most kMaxConfigBytes;
///  - encoding: valid UTF-8 (no overlong forms, surrogates or code points above U+10FFFF);
///    a byte-order mark only as the very first character;
///  - characters: no control character other than tab, CR and LF (C0, DEL, C1);
///  - the subset kfd's keys need: a map of scalars and stages' maps, or the same map under
///    one top-level key (`kfd:`), at most kMaxYamlLevels levels; values plain or quoted scalars,
///    flow lists [a, b] (not nested) or block lists (- a). Outside comments none of { } & * ! % ? |
///    > @ ` (flow maps, anchors, aliases, tags, directives, complex keys, block scalars), no
///    document markers (--- or ...), no tab in indentation, no unterminated quote or list;
///  - no key twice in the same map (ConfigError naming the key).
void checkYamlText(const std::string& text);

/// checkYamlText(text), then MRPT's YAML parser, then loadYaml. `origin` names the text in
/// messages (e.g. "file x.yaml").
Pipeline::Params loadYamlText(const std::string& text, const std::string& origin = "",
                              const Pipeline::Params* base = nullptr,
                              std::vector<std::string>* notes = nullptr);

/// Reads a YAML map of the same keys: `pipeline`, the choice keys, and a map per stage
/// (`distance: {max_range: 30}`; flat keys as in loadIni). If the document has a top-level
/// `kfd:` map, that map is used; otherwise the top level itself.
Pipeline::Params loadYaml(const mrpt::containers::yaml& doc, const Pipeline::Params* base = nullptr,
                          std::vector<std::string>* notes = nullptr);

/// Loads a .ini/.cfg (section [KFD]) or .yaml/.yml file by extension (YAML through
/// loadYamlText; .ini keys set twice are a ConfigError, see checkIniText; so is
/// `pipeline =` with no stage). Throws ConfigError when the
/// file is missing, unreadable, or has no [KFD] section / kfd keys.
/// `notes`: what the user should know (flat keys read for this release), for the app to print.
Pipeline::Params loadConfigFile(const std::string& path, const std::string& section = "KFD",
                                std::vector<std::string>* notes = nullptr);

/// kfd's defaults for small indoor robots: share/kfd/default.ini, compiled in (kfd-filter
/// without -c, kfd-icp-slam without [KFD]). kfdDefaultIni() is that file's text.
Pipeline::Params kfdDefaults();
const char* kfdDefaultIni();

/// The effective configuration as .ini text: [KFD] with the pipeline, then a section per
/// listed stage, [KFD.<stage>], with every key of that stage at its current value.
std::string toIni(const Pipeline::Params& p, const std::string& section = "KFD");

}  // namespace kfd
