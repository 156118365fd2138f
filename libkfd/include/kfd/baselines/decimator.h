// Uniform decimation (baseline, beyond the paper): keep a fixed share of the scans, evenly.
#pragma once

#include "kfd/pipeline/error.h"

namespace kfd {

/// Keeps `keep_fraction` f of the scans, spread evenly by count: scan n (from 0) is kept when
/// n = 0 or floor(n f) > floor((n - 1) f), computed with an accumulator (a = 1 before the first
/// scan; keep when a >= 1 - 1e-9, then a -= 1; a += f after every scan). f = 1 keeps every
/// scan, f = 1/k every k-th (the 1st, the (k+1)-th, ...); f = 0.3 keeps scans 0, 4, 7, 10, ...
/// Needs neither odometry nor the scan's contents: the strongest simple alternative for a robot
/// without wheel odometry, at the drop rate 100 (1 - f) % of another method.
class Decimator {
  public:
    struct Params {
        double keep_fraction = 0.5;  // share of scans kept, (0, 1]
    };

    Decimator() = default;
    explicit Decimator(const Params& p) { initialize(p); }
    /// kfd::ParameterError unless 0 < keep_fraction <= 1.
    void initialize(const Params& p);
    const Params& params() const { return params_; }

    /// True when this scan is kept.
    bool keep();
    void reset() { acc_ = 1.0; }

  private:
    Params params_;
    double acc_ = 1.0;
};

}  // namespace kfd
