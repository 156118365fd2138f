#include "kfd/os/cancel.h"

#include <atomic>

namespace kfd {
namespace {

std::atomic<int> g_signal{0};
static_assert(std::atomic<int>::is_always_lock_free, "the cancel flag must be signal-safe");

}  // namespace

Cancelled::Cancelled(int signal)
    : Error("interrupted by signal " + std::to_string(signal) + "; no output written"),
      signal_(signal) {}

void requestCancel(int signal) noexcept { g_signal.store(signal, std::memory_order_relaxed); }
int cancelRequested() noexcept { return g_signal.load(std::memory_order_relaxed); }
void resetCancel() noexcept { g_signal.store(0, std::memory_order_relaxed); }
void throwIfCancelled() {
    if (const int s = cancelRequested()) throw Cancelled(s);
}

}  // namespace kfd
