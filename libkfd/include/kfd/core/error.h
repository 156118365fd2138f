// kfd's one exception root: every library exception derives from kfd::Error (std only).
#pragma once

#include <stdexcept>
#include <string>
#include <utility>

namespace kfd {

/// Base of every exception thrown by kfd's libraries. `field()` names what was wrong when that
/// is known: a parameter (core), a configuration key (config layer), a flag, or a file and line.
class Error : public std::runtime_error {
  public:
    explicit Error(const std::string& message, std::string field = {})
        : std::runtime_error(message), field_(std::move(field)) {}
    const std::string& field() const { return field_; }

  private:
    std::string field_;
};

/// A parameter outside its documented range; `field()` is the parameter's name in its Params
/// struct (e.g. "m_threshold"). The config layer maps it to the user's key.
class ParameterError : public Error {
  public:
    ParameterError(const std::string& field, const std::string& message)
        : Error(field + ": " + message, field) {}
};

}  // namespace kfd
