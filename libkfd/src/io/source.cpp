#include "kfd/io/source.h"

#include <mrpt/core/Clock.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CObservationOdometry.h>

#include <cmath>
#include <limits>

namespace kfd {
namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
}  // namespace

double stampOf(const mrpt::obs::CObservation& obs) {
    return obs.timestamp == mrpt::Clock::time_point() ? std::numeric_limits<double>::quiet_NaN()
                                                      : mrpt::Clock::toDouble(obs.timestamp);
}

void OdometryTracker::onAction(const mrpt::obs::CActionCollection& actions) {
    if (auto mv = actions.getBestMovementEstimation()) {
        const auto& d = mv->rawOdometryIncrementReading;
        if (!finitePose(d.x(), d.y(), d.phi())) {  // this reading only is bad (kfd::checkScan)
            current_ = Pose2D{kNaN, kNaN, kNaN};
            return;
        }
        accum_ = accum_ + d;
        current_ = Pose2D{accum_.x(), accum_.y(), accum_.phi()};
    }
}

void OdometryTracker::onObservation(const mrpt::obs::CObservation& obs) {
    if (const auto* odo = dynamic_cast<const mrpt::obs::CObservationOdometry*>(&obs))
        current_ = Pose2D{odo->odometry.x(), odo->odometry.y(), odo->odometry.phi()};
}

bool finitePose(double x, double y, double phi) {
    return std::isfinite(x) && std::isfinite(y) && std::isfinite(phi);
}

const char* toString(LogFormat f) {
    switch (f) {
        case LogFormat::Rawlog:
            return "MRPT rawlog";
        case LogFormat::Bag:
            return "ROS 1 bag";
        case LogFormat::Carmen:
            return "CARMEN log";
        case LogFormat::Rosbag2:
            return "rosbag2";
        case LogFormat::Mcap:
            return "MCAP";
    }
    return "?";
}

}  // namespace kfd
