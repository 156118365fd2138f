// A per-thread cap on single allocations while MRPT decodes an object of an input file.
//
// MRPT's deserialisers trust the length fields they read: a corrupt string or vector length
// makes them resize to up to 4 GiB (zero-filled, so really used) before the read fails. A
// RawlogSource therefore sets, around each object it decodes, a limit of the decoded bytes
// left in the file plus kAllocationSlack: no well-formed object needs one allocation larger
// than the data it is decoded from by more than that.
//
// The limit is enforced by kfd's replacement of the global allocation functions
// (operator new / new[], plain and nothrow: the kfd::alloc_limit object library, which every
// kfd app and fuzz target links). A program that does not link it reads rawlogs as MRPT does,
// without the bound. Not covered: MRPT's aligned vectors (scan ranges), which allocate with
// mrpt::aligned_malloc rather than operator new.
#pragma once

#include <cstddef>

namespace kfd {

/// Added to the bytes left in the file: 64 MiB.
inline constexpr std::size_t kAllocationSlack = std::size_t{64} << 20;

/// The current thread's cap on one allocation, in bytes (SIZE_MAX when none is set).
std::size_t allocationLimit() noexcept;

/// Sets the current thread's cap for its lifetime, then restores the previous one.
class ScopedAllocationLimit {
  public:
    explicit ScopedAllocationLimit(std::size_t bytes) noexcept;
    ~ScopedAllocationLimit();
    ScopedAllocationLimit(const ScopedAllocationLimit&) = delete;
    ScopedAllocationLimit& operator=(const ScopedAllocationLimit&) = delete;

  private:
    std::size_t previous_;
};

}  // namespace kfd
