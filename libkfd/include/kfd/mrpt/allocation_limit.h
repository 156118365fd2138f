// A per-thread cap on single allocations while MRPT decodes an object of an input file.
//
// MRPT's deserialisers trust the length fields they read: a corrupt string or vector length
// makes them resize to up to 4 GiB (zero-filled, so really used) before the read fails; a
// scan's beam count sizes three arrays at once (9.5 GB for 0x40000000). A RawlogSource
// therefore sets, around each object it decodes, a limit of the decoded bytes left in the file
// plus kAllocationSlack: no well-formed object needs one allocation larger than the data it is
// decoded from by more than that.
//
// The limit is enforced by kfd's replacements of the allocation functions MRPT reaches (the
// kfd::alloc_limit object library, which every kfd app and fuzz target links): the global
// operator new / new[] (plain, nothrow and aligned) and mrpt::aligned_malloc, the allocator of
// MRPT's aligned vectors (a scan's ranges, validity and intensity arrays) and dynamic
// matrices. A refused allocation is std::bad_alloc, which RawlogSource reports as a corrupt
// length field. A program that does not link kfd::alloc_limit reads rawlogs as MRPT does,
// without the bound. Not covered: C allocation calls (malloc, posix_memalign), which
// libmrpt-obs does not make but Eigen's dynamic matrices (libmrpt-math, libmrpt-poses) and
// OpenCV's images (an image observation in a rawlog) do. Those do not zero what they allocate
// (a corrupt image size costs address space, not memory, until the read fails), and a size no
// malloc can give (fuzz_rawlog found 1.2e18 bytes: test/fuzz/corpus/rawlog/finding-*) returns
// null, which OpenCV turns into an exception: a clear error like the others.
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
