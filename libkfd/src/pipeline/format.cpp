#include "kfd/pipeline/format.h"

#include <cstdarg>
#include <cstdio>

namespace kfd {

std::string format(const char* fmt, ...) {
    std::va_list args;
    va_start(args, fmt);
    std::va_list again;
    va_copy(again, args);
    const int n = std::vsnprintf(nullptr, 0, fmt, args);
    va_end(args);
    std::string out;
    if (n > 0) {
        out.resize(static_cast<std::size_t>(n));
        std::vsnprintf(out.data(), out.size() + 1, fmt, again);  // C++17: data() is writable
    }
    va_end(again);
    return out;
}

std::string noun(std::size_t n, const std::string& word, const std::string& plural_form) {
    if (n == 1) return word;
    return plural_form.empty() ? word + "s" : plural_form;
}

std::string plural(std::size_t n, const std::string& word, const std::string& plural_form) {
    return std::to_string(n) + " " + noun(n, word, plural_form);
}

}  // namespace kfd
