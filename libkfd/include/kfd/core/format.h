// printf-style formatting into a std::string of the exact length (std only): numbers of any
// size, no fixed buffer to overflow or truncate (a 1e300 coordinate has 300 digits in %f).
#pragma once

#include <string>

namespace kfd {

/// The text std::printf(fmt, ...) would print.
std::string format(const char* fmt, ...) __attribute__((format(printf, 1, 2)));

}  // namespace kfd
