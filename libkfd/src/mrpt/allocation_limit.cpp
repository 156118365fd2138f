#include "kfd/mrpt/allocation_limit.h"

#include <cstdint>

namespace kfd {
namespace {
thread_local std::size_t t_limit = SIZE_MAX;
}  // namespace

std::size_t allocationLimit() noexcept { return t_limit; }

ScopedAllocationLimit::ScopedAllocationLimit(std::size_t bytes) noexcept : previous_(t_limit) {
    t_limit = bytes;
}

ScopedAllocationLimit::~ScopedAllocationLimit() { t_limit = previous_; }

}  // namespace kfd
