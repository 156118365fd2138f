// printf-style formatting into a std::string of the exact length (std only): numbers of any
// size, no fixed buffer to overflow or truncate (a 1e300 coordinate has 300 digits in %f).
// And counts with their noun in the right number ("1 scan", "2 scans").
#pragma once

#include <cstddef>
#include <string>

namespace kfd {

/// The text std::printf(fmt, ...) would print.
std::string format(const char* fmt, ...) __attribute__((format(printf, 1, 2)));

/// "1 scan", "0 scans", "2 scans": `n` and `word`, with `plural_form` (default: word + "s")
/// unless n is 1. E.g. plural(n, "entry", "entries"), plural(n, "scan") + " degenerate".
std::string plural(std::size_t n, const std::string& word, const std::string& plural_form = {});
/// The word alone, in the number of `n`: noun(2, "sensor") = "sensors".
std::string noun(std::size_t n, const std::string& word, const std::string& plural_form = {});

}  // namespace kfd
