#include "kfd/pipeline/stage_keys.h"

#include <cmath>
#include <cstdio>

namespace kfd {
namespace keys {

std::string formatReal(double v) {
    char buf[64];
    std::snprintf(buf, sizeof(buf), "%.10g", v);
    return buf;
}

double parseReal(const std::string& field, const std::string& t) {
    // Decimal only: strtod would also read hexadecimal ("0x10" as 16) and "inf"/"nan".
    if (t.empty() || t.find_first_not_of("0123456789+-.eE") != std::string::npos)
        throw ParameterError(field, "'" + t + "' is not a number");
    std::size_t pos = 0;
    double v = 0;
    try {
        v = std::stod(t, &pos);
    } catch (const std::exception&) {
        throw ParameterError(field, "'" + t + "' is not a number");
    }
    if (pos != t.size()) throw ParameterError(field, "'" + t + "' is not a number");
    if (!std::isfinite(v)) throw ParameterError(field, "'" + t + "' is not finite");
    return v;
}

std::string realRange(double lo, double hi, bool lo_open) {
    return std::string(lo_open ? "(" : "[") + formatReal(lo) + ", " + formatReal(hi) + "]";
}

void checkReal(const std::string& field, double v, double lo, double hi, bool lo_open) {
    if ((lo_open ? v <= lo : v < lo) || v > hi)
        throw ParameterError(field,
                             formatReal(v) + " is out of range " + realRange(lo, hi, lo_open));
}

std::string countRange(double lo, double hi) {
    return "[" + formatReal(lo) + ", " + formatReal(hi) + "], integer";
}

std::size_t parseCount(const std::string& field, const std::string& text, double lo, double hi) {
    const double v = parseReal(field, text);
    if (v != std::floor(v)) throw ParameterError(field, text + " is not an integer");
    if (v < lo || v > hi)
        throw ParameterError(field, formatReal(v) + " is out of range " + countRange(lo, hi));
    return static_cast<std::size_t>(v);
}

}  // namespace keys
}  // namespace kfd
