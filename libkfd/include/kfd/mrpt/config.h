// Configuration of the kfd pipeline from an MRPT-style .ini section or from YAML.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "kfd/core/pipeline.h"

namespace mrpt::config {
class CConfigFileBase;
}
namespace mrpt::containers {
class yaml;
}

namespace kfd {

/// A configuration problem. `key()` names the offending key (empty for file-level problems).
class ConfigError : public std::runtime_error {
  public:
    ConfigError(const std::string& key, const std::string& message)
        : std::runtime_error(key.empty() ? message : "config key '" + key + "': " + message),
          key_(key) {}
    const std::string& key() const { return key_; }

  private:
    std::string key_;
};

/// One recognised key: name, meaning (with unit), and the allowed values.
struct ConfigKeyInfo {
    std::string name;
    std::string help;
    std::string range;
};
/// Every key the loaders accept, in documentation order.
const std::vector<ConfigKeyInfo>& configKeys();

/// Reads the keys of `section` (default "KFD") over the defaults of Pipeline::Params.
/// Unknown keys and out-of-range values throw ConfigError naming the key. Other sections are
/// ignored, so the [KFD] section can live inside an icp-slam .ini.
Pipeline::Params loadIni(const mrpt::config::CConfigFileBase& cfg,
                         const std::string& section = "KFD");

/// Reads a YAML map of the same keys. If the document has a top-level `kfd:` map, that map is
/// used; otherwise the top level itself.
Pipeline::Params loadYaml(const mrpt::containers::yaml& doc);

/// Loads a .ini/.cfg (section [KFD]) or .yaml/.yml file by extension. Throws ConfigError when the
/// file is missing, unreadable, or has no [KFD] section / kfd keys.
Pipeline::Params loadConfigFile(const std::string& path, const std::string& section = "KFD");

/// The effective configuration as an .ini [KFD] section (every key, current values).
std::string toIni(const Pipeline::Params& p, const std::string& section = "KFD");

}  // namespace kfd
