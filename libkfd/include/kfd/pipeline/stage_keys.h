// Builders for a stage's configuration keys: text -> range-checked Params field -> text (std only).
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <utility>

#include "kfd/pipeline/error.h"
#include "kfd/pipeline/stage.h"

namespace kfd {
namespace keys {

/// "%.10g", the form in which the config layer prints real values.
std::string formatReal(double v);
/// A finite number; kfd::ParameterError(field) otherwise.
double parseReal(const std::string& field, const std::string& text);
/// "[lo, hi]" or "(lo, hi]".
std::string realRange(double lo, double hi, bool lo_open);
/// Checks v against realRange(lo, hi, lo_open); kfd::ParameterError(field) when outside.
void checkReal(const std::string& field, double v, double lo, double hi, bool lo_open);
/// A whole number in [lo, hi]; kfd::ParameterError(field) otherwise.
std::size_t parseCount(const std::string& field, const std::string& text, double lo, double hi);
/// "[lo, hi], integer".
std::string countRange(double lo, double hi);

/// A real key in [lo, hi] (or (lo, hi] when lo_open) bound to the double that `at` returns.
template <class P, class At>
StageKey real(std::string name, std::string field, std::string help, double lo, double hi,
              bool lo_open, At at) {
    StageKey k{
        std::move(name), std::move(field), std::move(help), realRange(lo, hi, lo_open), {}, {}};
    k.set = [f = k.field, lo, hi, lo_open, at](void* p, const std::string& text) {
        const double v = parseReal(f, text);
        checkReal(f, v, lo, hi, lo_open);
        at(*static_cast<P*>(p)) = v;
    };
    k.get = [at](const void* p) {
        return formatReal(at(*const_cast<P*>(static_cast<const P*>(p))));
    };
    return k;
}

/// A whole-number key in [lo, hi] bound to the std::size_t that `at` returns.
template <class P, class At>
StageKey count(std::string name, std::string field, std::string help, double lo, double hi, At at) {
    StageKey k{std::move(name), std::move(field), std::move(help), countRange(lo, hi), {}, {}};
    k.set = [f = k.field, lo, hi, at](void* p, const std::string& text) {
        at(*static_cast<P*>(p)) = parseCount(f, text, lo, hi);
    };
    k.get = [at](const void* p) {
        return std::to_string(at(*const_cast<P*>(static_cast<const P*>(p))));
    };
    return k;
}

/// A true/false key ("1"/"0" accepted) bound to the bool that `at` returns;
/// kfd::ParameterError(field) "FIELD must be true or false, not 'TEXT'" otherwise.
template <class P, class At>
StageKey boolean(std::string name, std::string field, std::string help, At at) {
    StageKey k{std::move(name), std::move(field), std::move(help), "true, false", {}, {}};
    k.set = [f = k.field, at](void* p, const std::string& text) {
        if (text == "true" || text == "1")
            at(*static_cast<P*>(p)) = true;
        else if (text == "false" || text == "0")
            at(*static_cast<P*>(p)) = false;
        else
            throw ParameterError(f, f + " must be true or false, not '" + text + "'");
    };
    k.get = [at](const void* p) {
        return std::string(at(*const_cast<P*>(static_cast<const P*>(p))) ? "true" : "false");
    };
    return k;
}

/// A key with its own parser and printer.
template <class P>
StageKey custom(std::string name, std::string field, std::string help, std::string range,
                std::function<void(P&, const std::string&)> set,
                std::function<std::string(const P&)> get) {
    StageKey k{std::move(name), std::move(field), std::move(help), std::move(range), {}, {}};
    k.set = [set](void* p, const std::string& text) { set(*static_cast<P*>(p), text); };
    k.get = [get](const void* p) { return get(*static_cast<const P*>(p)); };
    return k;
}

}  // namespace keys
}  // namespace kfd
