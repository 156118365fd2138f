// A sensor's scan rate from its stamps (std only): the mean rate over the whole log and the
// median interval, which differ when the log has gaps or bursts (kfd-filter's summary prints
// both).
#pragma once

#include <cstddef>
#include <vector>

namespace kfd {

struct ScanRate {
    std::size_t stamps = 0;          // finite stamps counted
    double span_s = 0.0;             // s, latest stamp - earliest stamp
    double mean_hz = 0.0;            // (stamps - 1) / span_s; 0 when the span is not > 0
    double median_interval_s = 0.0;  // s, median of the positive intervals; 0 when none
};

/// Counts stamps one at a time (a scan each), in log order. Memory: one float per scan.
class ScanRateMeter {
  public:
    /// A scan's stamp (s). Non-finite stamps are ignored; an interval that is not positive (a
    /// repeated or backward stamp) counts for the span, not for the median.
    void add(double t);
    ScanRate result() const;

  private:
    std::size_t stamps_ = 0;
    double last_ = 0.0, min_ = 0.0, max_ = 0.0;
    std::vector<float> intervals_;
};

}  // namespace kfd
