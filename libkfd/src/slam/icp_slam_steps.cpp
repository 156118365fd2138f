#include "icp_slam_steps.h"

#include <algorithm>

#include "kfd/io/open_source.h"
#include "kfd/slam/icp_slam_runner.h"

namespace kfd::icp_slam {

using mrpt::obs::CObservation2DRangeScan;

std::unique_ptr<Source> openLog(const std::string& path, const SourceOptions& options) {
    try {
        return openSource(path, options);
    } catch (const SourceError& e) {
        throw SlamError(e.what(), path);
    }
}

bool nextEntry(Source& source, SourceEntry& e) {
    try {
        return source.next(e);
    } catch (const SourceError& err) {
        throw SlamError(err.what(), source.path());
    }
}

std::size_t scanCount(const IcpSlamStep& step) {
    if (step.observation) return IS_CLASS(*step.observation, CObservation2DRangeScan) ? 1 : 0;
    std::size_t n = 0;
    for (const auto& o : *step.frame) n += IS_CLASS(*o, CObservation2DRangeScan) ? 1 : 0;
    return n;
}

bool StartSkipper::skip(const IcpSlamStep& step) {
    if (left_ == 0) return false;
    const std::size_t n = scanCount(step);
    skipped_ += n;
    left_ -= std::min(left_, n);
    return true;
}

}  // namespace kfd::icp_slam
