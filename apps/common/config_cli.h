// kfd's configuration as the apps read it: the file (kfd::loadConfigFile), or kfd's defaults
// without one, and what the user should know about it (flat keys read for this release) on
// stderr.
#pragma once

#include <cstdio>
#include <string>
#include <vector>

#include "kfd/mrpt/config.h"

namespace kfd::app {

/// kfd::loadConfigFile(path), its notes printed as "<app>: note: ..."; kfdDefaults() when
/// `path` is empty.
inline kfd::Pipeline::Params loadConfig(const std::string& path, const char* app) {
    if (path.empty()) return kfd::kfdDefaults();
    std::vector<std::string> notes;
    kfd::Pipeline::Params p = kfd::loadConfigFile(path, "KFD", &notes);
    for (const std::string& n : notes) std::fprintf(stderr, "%s: note: %s\n", app, n.c_str());
    return p;
}

}  // namespace kfd::app
