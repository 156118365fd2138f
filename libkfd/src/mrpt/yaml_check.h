// The YAML pre-check of the configuration loader (private to libkfd): the text is checked before
// MRPT's YAML parser sees it. Its public name is kfd::checkYamlText (kfd/mrpt/config.h), which
// documents the rules; config.cpp calls checkYaml through it.
#pragma once

#include <string>
#include <vector>

namespace kfd::detail {

/// The lines of `text` (LF or CRLF, the CR removed), the first being line 1 (also how the .ini
/// check, kfd::checkIniText, numbers lines).
std::vector<std::string> splitLines(const std::string& text);

/// kfd::checkYamlText: size, encoding, characters, then the YAML subset kfd's keys need;
/// ConfigError (file level, or naming the key) on the first problem.
void checkYaml(const std::string& text);

}  // namespace kfd::detail
