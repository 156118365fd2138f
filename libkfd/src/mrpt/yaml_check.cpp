// The YAML pre-check (yaml_check.h): kfd::checkYamlText's rules, in the order of its
// documentation (kfd/mrpt/config.h).
#include "yaml_check.h"

#include <mrpt/system/string_utils.h>

#include <map>

#include "kfd/mrpt/config.h"

namespace kfd::detail {
namespace {

using mrpt::system::trim;

// 1-based line of byte `pos` of `text`.
std::size_t lineOf(const std::string& text, std::size_t pos) {
    std::size_t n = 1;
    for (std::size_t i = 0; i < pos && i < text.size(); ++i) n += (text[i] == '\n');
    return n;
}

}  // namespace

std::vector<std::string> splitLines(const std::string& text) {
    std::vector<std::string> lines;
    std::size_t start = 0;
    while (start <= text.size()) {
        std::size_t end = text.find('\n', start);
        if (end == std::string::npos) end = text.size();
        std::string line = text.substr(start, end - start);
        if (!line.empty() && line.back() == '\r') line.pop_back();
        lines.push_back(line);
        start = end + 1;
    }
    return lines;
}

namespace {

// 1. Encoding: UTF-8 (RFC 3629: no overlong forms, no surrogates, at most U+10FFFF), an
//    optional byte-order mark at the very start only. 2. Characters: no control character
//    but tab, CR and LF (C0, DEL, C1). Returns where the text after the byte-order mark starts.
std::size_t checkEncoding(const std::string& text) {
    // 1. Encoding: UTF-8 (RFC 3629: no overlong forms, no surrogates, at most U+10FFFF), an
    //    optional byte-order mark at the very start only. 2. Characters: no control character
    //    but tab, CR and LF (C0, DEL, C1).
    const auto* b = reinterpret_cast<const unsigned char*>(text.data());
    const std::size_t n = text.size();
    std::size_t i = (n >= 3 && b[0] == 0xEF && b[1] == 0xBB && b[2] == 0xBF) ? 3 : 0;
    const std::size_t body = i;
    while (i < n) {
        const unsigned c = b[i];
        const auto where = [&] { return " at line " + std::to_string(lineOf(text, i)); };
        if (c < 0x80) {
            if ((c < 0x20 && c != '\t' && c != '\n' && c != '\r') || c == 0x7F)
                throw ConfigError("", "YAML: control character " + std::to_string(c) + where());
            ++i;
            continue;
        }
        std::size_t len = 0;
        unsigned cp = 0;
        if (c >= 0xC2 && c <= 0xDF)
            len = 2, cp = c & 0x1F;
        else if (c >= 0xE0 && c <= 0xEF)
            len = 3, cp = c & 0x0F;
        else if (c >= 0xF0 && c <= 0xF4)
            len = 4, cp = c & 0x07;
        else
            throw ConfigError("", "YAML: not UTF-8" + where());
        if (i + len > n) throw ConfigError("", "YAML: not UTF-8 (cut sequence)" + where());
        for (std::size_t k = 1; k < len; ++k) {
            if ((b[i + k] & 0xC0) != 0x80) throw ConfigError("", "YAML: not UTF-8" + where());
            cp = (cp << 6) | (b[i + k] & 0x3F);
        }
        if ((len == 3 && cp < 0x800) || (len == 4 && (cp < 0x10000 || cp > 0x10FFFF)) ||
            (cp >= 0xD800 && cp <= 0xDFFF))
            throw ConfigError("", "YAML: not UTF-8 (overlong or invalid code point)" + where());
        if ((cp >= 0x80 && cp <= 0x9F) || cp == 0xFEFF)
            throw ConfigError("", "YAML: control character or byte-order mark" + where());
        i += len;
    }
    return body;
}

// One line of the subset (step 3) with its comment stripped: ConfigError on an unterminated
// quote.
std::string stripComment(const std::string& raw, const std::string& at) {
    std::string line;
    char quote = 0;
    for (std::size_t k = 0; k < raw.size(); ++k) {
        const char c = raw[k];
        if (quote) {
            if (c == quote) quote = 0;
        } else if (c == '\'' || c == '"') {
            quote = c;
        } else if (c == '#' && (k == 0 || raw[k - 1] == ' ' || raw[k - 1] == '\t')) {
            break;
        }
        line += c;
    }
    if (quote) throw ConfigError("", "YAML: unterminated quote" + at);
    return line;
}

// The characters and lists of a line's content (step 3): none of { } & * ! % ? | > @ `, no
// nested or unbalanced list.
void checkContent(const std::string& content, const std::string& at) {
    if (content.rfind("---", 0) == 0 || content.rfind("...", 0) == 0)
        throw ConfigError("", "YAML: document markers (---, ...) are not supported" + at);
    int depth = 0;
    for (const char c : content) {
        if (std::string("{}&*!%?|>@`").find(c) != std::string::npos)
            throw ConfigError("", std::string("YAML: '") + c +
                                      "' is not supported (kfd reads a map of plain "
                                      "values and lists)" +
                                      at);
        if (c == '[' && ++depth > 1) throw ConfigError("", "YAML: nested list" + at);
        if (c == ']' && --depth < 0) throw ConfigError("", "YAML: unbalanced ']'" + at);
    }
    if (depth != 0) throw ConfigError("", "YAML: unterminated list" + at);
}

}  // namespace

void checkYaml(const std::string& text) {
    if (text.size() > kMaxConfigBytes)
        throw ConfigError("",
                          "YAML file larger than " + std::to_string(kMaxConfigBytes) + " bytes");
    const std::size_t body = checkEncoding(text);
    // 3. The subset kfd's keys need: a map of scalars (or the same under one `kfd:` key),
    //    values plain or quoted scalars, flow lists [a, b] or block lists (- a). Outside
    //    comments none of { } & * ! % ? | > @ ` (flow maps, anchors, aliases, tags,
    //    directives, complex keys, block scalars, reserved), no document markers (--- ...),
    //    no nested lists, no tab in indentation, at most three levels (kfd: / a stage / its
    //    keys); no key twice in a map.
    const auto lines = splitLines(text.substr(body));
    std::map<std::string, std::size_t> seen;              // "a/b/key" -> line
    std::vector<std::pair<std::size_t, std::string>> up;  // the maps above: (indent, key)
    for (std::size_t ln = 0; ln < lines.size(); ++ln) {
        const std::string& raw = lines[ln];
        const std::string at = " at line " + std::to_string(ln + 1);
        // Strip a comment: '#' at the start or after a blank, outside quotes.
        const std::string line = stripComment(raw, at);
        std::size_t indent = 0;
        while (indent < line.size() && (line[indent] == ' ' || line[indent] == '\t')) {
            if (line[indent] == '\t') throw ConfigError("", "YAML: tab in indentation" + at);
            ++indent;
        }
        const std::string content = trim(line);
        if (content.empty()) continue;
        checkContent(content, at);
        if (content[0] == '-') {  // block list item of the key above
            if (indent == 0 && up.empty()) throw ConfigError("", "YAML: a list is not a map" + at);
            continue;
        }
        const auto colon = content.find(':');
        if (colon == std::string::npos) continue;  // a continued plain scalar: the parser decides
        std::string key = trim(content.substr(0, colon));
        if (key.size() >= 2 && (key[0] == '\'' || key[0] == '"') && key.back() == key[0])
            key = key.substr(1, key.size() - 2);
        while (!up.empty() && up.back().first >= indent) up.pop_back();
        if (indent > 0 && up.empty())
            throw ConfigError(key, "YAML: indented key without a map above it" + at);
        if (up.size() >= kMaxYamlLevels)
            throw ConfigError(
                key, "YAML: more than " + std::to_string(kMaxYamlLevels) + " levels of maps" + at);
        std::string path;
        for (const auto& u : up) path += u.second + "/";
        const auto [it, inserted] = seen.emplace(path + key, ln + 1);
        if (!inserted)
            throw ConfigError(key, "set twice (lines " + std::to_string(it->second) + " and " +
                                       std::to_string(ln + 1) + ")");
        up.emplace_back(indent, key);
    }
}

}  // namespace kfd::detail
