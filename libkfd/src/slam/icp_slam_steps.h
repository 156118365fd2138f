// kfd-icp-slam's step grouping: the log read as MRPT's icp-slam reads it (an observation on its
// own, or an odometry action with the next sensory frame), the skipped start, and every scan of
// the run for the pre-passes. Internal to kfd_slam.
#pragma once

#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CSensoryFrame.h>

#include <cstddef>
#include <memory>
#include <optional>
#include <string>

#include "kfd/io/source.h"
#include "kfd/os/cancel.h"

namespace kfd::icp_slam {

// One step of MRPT's icp-slam: an observation on its own, or an odometry action with a sensory
// frame.
struct IcpSlamStep {
    mrpt::obs::CObservation::Ptr observation;
    mrpt::obs::CActionCollection::Ptr action;
    mrpt::obs::CSensoryFrame::Ptr frame;
};

// MRPT's icp-slam reads the log with CRawlog::getActionObservationPairOrObservation: an
// observation on its own is one step; an action is paired with the next sensory frame, and
// whatever lies between them (even another action or observation) is skipped, as is a frame
// without an action. This reproduces that grouping over a source's entries.
class IcpSlamSteps {
  public:
    /// True when `e` completes a step, written to `step`.
    bool feed(const SourceEntry& e, IcpSlamStep& step) {
        using Kind = SourceEntry::Kind;
        step = IcpSlamStep();
        if (waiting_action_) {  // an action waiting for its frame
            if (e.kind != Kind::Frame) return false;
            step.action = std::move(waiting_action_);
            step.frame = e.frame;
            return true;
        }
        if (e.kind == Kind::Observation) {
            step.observation = e.observation;
            return true;
        }
        if (e.kind == Kind::Frame && e.action) {
            step.action = e.action;
            step.frame = e.frame;
            return true;
        }
        if (e.kind == Kind::Action) waiting_action_ = e.action;
        return false;
    }

  private:
    mrpt::obs::CActionCollection::Ptr waiting_action_;
};

// The log's source; what cannot be opened or read is a SlamError naming the log.
std::unique_ptr<Source> openLog(const std::string& path, const SourceOptions& options);
bool nextEntry(Source& source, SourceEntry& e);

// The 2D scans of one step.
std::size_t scanCount(const IcpSlamStep& step);

// IcpSlamOptions::skip_scans: true for every step until the first K scans have gone by.
class StartSkipper {
  public:
    explicit StartSkipper(std::size_t k) : left_(k) {}
    bool skip(const IcpSlamStep& step);
    std::size_t skipped() const { return skipped_; }

  private:
    std::size_t left_, skipped_ = 0;
};

// Every 2D scan of the log as the real run meets it (icp-slam's steps, after the skipped
// start), with its entry's odometry: what the pre-passes that match a drop rate read.
template <class Fn>
void forEachRunScan(const std::string& rawlog, const SourceOptions& options, std::size_t skip_scans,
                    Fn&& fn) {
    auto source = openLog(rawlog, options);
    IcpSlamSteps steps;
    IcpSlamStep step;
    StartSkipper skipper(skip_scans);
    SourceEntry e;
    while (nextEntry(*source, e)) {
        throwIfCancelled();
        if (!steps.feed(e, step) || skipper.skip(step)) continue;
        auto visit = [&](const mrpt::obs::CObservation::Ptr& o) {
            if (auto scan = std::dynamic_pointer_cast<mrpt::obs::CObservation2DRangeScan>(o))
                fn(scan, e.odometry);
        };
        if (step.observation)
            visit(step.observation);
        else
            for (const auto& o : *step.frame) visit(o);
    }
}

}  // namespace kfd::icp_slam
