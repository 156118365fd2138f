// ICP's verdicts in kfd-icp-slam: MRPT's map builder says how each correction went only in its
// log text ("Fit:%.1f%%" when accepted, "Ignoring ICP of low quality: X" when rejected); this
// reads them and counts each correction: accepted (its goodness joins the gap check's),
// rejected by the SLAM's own minimum, or rejected by kfd's gap check only. Internal to kfd_slam.
#pragma once

#include <optional>
#include <string_view>
#include <vector>

#include "kfd/slam/gap_check.h"
#include "kfd/slam/icp_slam_runner.h"

namespace kfd::icp_slam {

/// A line of MRPT's map-builder log that carries a correction's goodness (0..1): accepted or
/// rejected. nullopt for any other line, or a number that is not finite.
struct IcpLogVerdict {
    double goodness = 0.0;
    bool rejected = false;
};
std::optional<IcpLogVerdict> parseIcpLogLine(std::string_view msg);

class IcpVerdicts {
  public:
    enum class Verdict { Accepted, Rejected, GapCheckFailed };

    /// `min_goodness`: the configuration's minICPgoodnessToAccept.
    explicit IcpVerdicts(double min_goodness) : min_goodness_(min_goodness), gap_(min_goodness) {}

    /// The map builder's log callback: a correction's line sets the current one.
    void onBuilderLog(std::string_view msg) {
        if (const auto v = parseIcpLogLine(msg)) current_ = v;
    }
    /// Did ICP run since clear()? Then goodness() and rejected() are the correction's.
    bool ran() const { return current_.has_value(); }
    double goodness() const { return current_->goodness; }
    bool rejected() const { return current_->rejected; }
    void clear() { current_.reset(); }

    /// The current correction (ran() must be true), counted in sum's icp_runs, icp_rejected and
    /// gap_checks_failed (a goodness above the configuration's minimum that only the gap check
    /// rejected).
    Verdict count(IcpSlamSummary& sum);

    double minimum() const { return min_goodness_; }      // the configuration's
    double gapMinimum() const { return gap_.minimum(); }  // after drops (GapCheck)
    std::optional<double> median() const;                 // of every counted goodness

  private:
    double min_goodness_;
    GapCheck gap_;
    std::optional<IcpLogVerdict> current_;
    std::vector<double> goodness_;
};

}  // namespace kfd::icp_slam
