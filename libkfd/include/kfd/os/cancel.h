// Cooperative cancellation (std only): a signal handler in an app calls requestCancel(); the
// libraries' long loops call throwIfCancelled(), so that the run unwinds, its temporary outputs
// are removed by their owners, and the app exits non-zero. Libraries never install handlers.
#pragma once

#include <string>

#include "kfd/pipeline/error.h"

namespace kfd {

/// A run stopped by requestCancel(); `signal()` is the number passed to it.
class Cancelled : public Error {
  public:
    explicit Cancelled(int signal);
    int signal() const { return signal_; }

  private:
    int signal_;
};

/// Asks every running loop to stop. Async-signal-safe (stores to a lock-free atomic).
void requestCancel(int signal) noexcept;
/// The number given to requestCancel(), 0 when none.
int cancelRequested() noexcept;
/// Clears a request (tests).
void resetCancel() noexcept;
/// Throws Cancelled when requestCancel() was called.
void throwIfCancelled();

}  // namespace kfd
