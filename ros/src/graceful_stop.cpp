#include "kfd/ros1/graceful_stop.h"

#include <ros/init.h>
#include <ros/xmlrpc_manager.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <map>
#include <mutex>
#include <thread>

namespace kfd::ros1 {

namespace {

volatile std::sig_atomic_t g_signals = 0;  // SIGINT/SIGTERM received
std::atomic<bool> g_asked{false};          // the master's shutdown call

void onSignal(int) {
    if (g_signals++ > 0) ros::requestShutdown();  // the second one: at once (as roscpp's own)
}

struct State {
    std::mutex mutex;
    std::map<std::size_t, std::function<void()>> finishers;
    std::size_t next = 1;
    bool bound = false;  // the XML-RPC shutdown is ours (stays: with none registered, it stops)
    struct sigaction old_int {
    }, old_term{};
    std::thread watcher;
    std::atomic<bool> quit{false};
};

State& state() {
    static State* s = new State;  // never destroyed: signal handlers and threads may outlive
    return *s;                    // static destruction
}

void onShutdownCall(XmlRpc::XmlRpcValue&, XmlRpc::XmlRpcValue& result) {
    {
        std::lock_guard<std::mutex> lock(state().mutex);
        if (state().finishers.empty())
            ros::requestShutdown();  // nothing held: roscpp's own behaviour
        else
            g_asked = true;
    }
    result = ros::xmlrpc::responseInt(1, "", 0);
}

// The stop's thread: waits for a stop, runs the finishers, lets their messages go, stops ROS.
void watch() {
    State& s = state();
    while (!s.quit) {
        if (GracefulStop::requested()) {
            {
                std::lock_guard<std::mutex> lock(s.mutex);
                for (auto& [token, finish] : s.finishers) finish();
            }
            std::this_thread::sleep_for(std::chrono::milliseconds(500));
            ros::requestShutdown();
            return;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
}

void install(State& s) {
    struct sigaction a {};
    a.sa_handler = onSignal;
    sigemptyset(&a.sa_mask);
    sigaction(SIGINT, &a, &s.old_int);
    sigaction(SIGTERM, &a, &s.old_term);
    if (!s.bound) {
        ros::XMLRPCManager::instance()->unbind("shutdown");
        ros::XMLRPCManager::instance()->bind("shutdown", onShutdownCall);
        s.bound = true;
    }
    s.quit = false;
    s.watcher = std::thread(watch);
}

}  // namespace

bool GracefulStop::requested() { return g_signals > 0 || g_asked; }

std::size_t GracefulStop::add(std::function<void()> finish) {
    State& s = state();
    std::lock_guard<std::mutex> lock(s.mutex);
    if (s.finishers.empty()) install(s);
    s.finishers.emplace(s.next, std::move(finish));
    return s.next++;
}

void GracefulStop::remove(std::size_t token) {
    State& s = state();
    std::thread watcher;
    {
        std::lock_guard<std::mutex> lock(s.mutex);
        if (!s.finishers.erase(token) || !s.finishers.empty()) return;
        sigaction(SIGINT, &s.old_int, nullptr);
        sigaction(SIGTERM, &s.old_term, nullptr);
        s.quit = true;
        watcher = std::move(s.watcher);
    }
    if (watcher.joinable() && watcher.get_id() != std::this_thread::get_id())
        watcher.join();
    else if (watcher.joinable())
        watcher.detach();
    // A stop asked for while the last filter was going (a manager's SIGINT racing the loader's
    // unload): the signal came to kfd's handler, so the stop it asked for is kfd's to pass on.
    if (GracefulStop::requested()) ros::requestShutdown();
}

}  // namespace kfd::ros1
