// Every way a ROS 1 process is asked to stop finishes what kfd holds first (issue 38): SIGINT,
// SIGTERM (roslaunch, Ctrl-C, kill) and the master's `shutdown` call (rosnode kill, a node of
// the same name starting) reach the registered filters, which publish a keyframe held for its
// next scan and their last stats; ROS stops 0.5 s later (the messages reach the subscribers).
// A second signal stops ROS at once. Process-wide: kfd_node and every kfd nodelet of a manager
// register; with the last one gone the manager's own signal handlers are back.
#pragma once

#include <cstddef>
#include <functional>

namespace kfd::ros1 {

class GracefulStop {
  public:
    /// Registers `finish`, run once on the stop's own thread when a stop is asked for; the
    /// first registration installs the handlers. Returns the token for remove().
    static std::size_t add(std::function<void()> finish);
    /// Unregisters; the last one restores the signal handlers found at the first add().
    static void remove(std::size_t token);
    /// A stop was asked for (the registered filters drop scans from then on).
    static bool requested();
};

}  // namespace kfd::ros1
