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
    explicit Error(const std::string& message, std::string field = {}, std::string detail = {})
        : std::runtime_error(message),
          field_(std::move(field)),
          detail_(detail.empty() ? message : std::move(detail)) {}
    const std::string& field() const { return field_; }
    /// The message without the field's name in front, for callers that name the field their
    /// own way (the config layer names the key, the command line names the flag).
    const std::string& detail() const { return detail_; }

  private:
    std::string field_;
    std::string detail_;
};

/// A parameter outside its documented range; `field()` is the parameter's name in its Params
/// struct (e.g. "m_threshold"). The config layer maps it to the user's key.
class ParameterError : public Error {
  public:
    ParameterError(const std::string& field, const std::string& message)
        : Error(field + ": " + message, field, message) {}
};

/// An exception's message as one line of words. MRPT's exceptions carry a banner
/// ("==== MRPT exception ====", "Message: ...", "Location: file:line", a call stack; nested ones
/// repeat it): the text before the banner is kept and the banner becomes its innermost message,
/// its lines joined with "; " ("cannot read [KFD]: ==== MRPT exception ====\nMessage:  X\n..."
/// -> "cannot read [KFD]: X"). Any other text is returned as it is.
std::string plainMessage(const std::string& what);

/// A scan the library cannot process as given (no beams, buffers of different sizes).
class ScanError : public Error {
  public:
    using Error::Error;
};

}  // namespace kfd
