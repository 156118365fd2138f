// Scan histogram: Sec. 3.1.2 ("Construct Histogram").
#pragma once

#include <cstddef>
#include <vector>

#include "kfd/pipeline/error.h"
#include "kfd/pipeline/scan.h"

namespace kfd {

/// Reduces a scan to n numbers: the field of view is cut into n equal angular intervals and
/// each bin holds the mean range (m) of the valid points inside it.
///
/// Beam i falls in bin floor(i * n / beams); because beams are equally spaced in angle this is
/// the equal-angle split of Sec. 3.1.2, computed without trigonometry.
///
/// Empty bin: a bin with no valid point holds 0. "Nothing returned in this direction" is then
/// the same value in every scan, so two scans that both see nothing there agree, and a scan that
/// suddenly sees nothing where it used to see a wall differs strongly.
class Histogram {
  public:
    struct Params {
        std::size_t bins = 20;  // n; the paper's value at 0.752 m/s (15 at 0.575 m/s)
    };

    Histogram() = default;
    explicit Histogram(const Params& p) { initialize(p); }

    /// Throws kfd::ParameterError when bins == 0.
    void initialize(const Params& p);
    const Params& params() const { return params_; }

    /// Fills `out` (resized to n; no allocation once sized) with the mean range per bin.
    /// Returns the number of non-empty bins.
    std::size_t compute(const Scan& scan, std::vector<double>& out) const;

  private:
    Params params_;
    mutable std::vector<std::size_t> counts_;  // scratch, reused between calls
};

}  // namespace kfd
