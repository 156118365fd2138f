#pragma once
/// \file
/// The gap check of kfd-icp-slam: how good an ICP correction across scans the pre-filter
/// dropped must be before the map builder may accept it. The level is the log's own (its
/// recent accepted corrections: sensor, environment and ICP settings), never below the SLAM
/// configuration's minimum. A correction below it is rejected and re-matched through the
/// dropped scans (docs/DESIGN.md, "Re-matching").

#include <cstddef>
#include <vector>

namespace kfd {

class GapCheck {
  public:
    struct Params {
        double median_share = 0.75;  // of the recent median goodness
        std::size_t recent = 64;     // accepted corrections that make "recent"
        std::size_t min_recent = 8;  // fewer: the configuration's minimum alone
    };

    /// `config_minimum`: the SLAM's own (MRPT's minICPgoodnessToAccept).
    explicit GapCheck(double config_minimum) : GapCheck(config_minimum, Params()) {}
    GapCheck(double config_minimum, Params p);

    /// An accepted correction's goodness (MRPT's share of matched points).
    void accepted(double goodness);

    /// What a correction across dropped scans must reach: median_share x the median of the
    /// last `recent` accepted corrections, or the configuration's minimum when that is higher
    /// or fewer than min_recent were accepted.
    double minimum() const;

    double configMinimum() const { return config_minimum_; }

  private:
    double config_minimum_;
    Params p_;
    std::vector<double> ring_;
    std::size_t next_ = 0;
};

}  // namespace kfd
