// The node's latency figures (subscriber callback entry to publish return), bounded memory.
#pragma once

#include <cstddef>
#include <vector>

namespace kfd::live {

/// Percentiles over the last `window` samples, the maximum over all of them.
class LatencyStats {
  public:
    explicit LatencyStats(std::size_t window = 4096) : window_(window ? window : 1) {}
    void add(double microseconds);
    /// The p-th percentile (0..100, nearest rank) of the samples in the window; 0 when empty.
    double percentile(double p) const;
    double max() const { return max_; }
    std::size_t count() const { return count_; }

  private:
    std::size_t window_;
    std::vector<double> ring_;
    std::size_t next_ = 0, count_ = 0;
    double max_ = 0.0;
};

}  // namespace kfd::live
