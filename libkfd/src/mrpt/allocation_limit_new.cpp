// kfd::alloc_limit: the global allocation functions with kfd::allocationLimit() enforced (see
// kfd/mrpt/allocation_limit.h). malloc-based like libstdc++'s own; every non-aligned form is
// replaced, new and delete together, so that each pointer is freed by its own allocator
// (the sanitizer runtimes check that pairing). The aligned forms stay the library's.
#include <cstdlib>
#include <new>

#include "kfd/mrpt/allocation_limit.h"

namespace {
void* allocate(std::size_t n) {
    if (n > kfd::allocationLimit()) throw std::bad_alloc();
    for (;;) {
        if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
        std::new_handler h = std::get_new_handler();
        if (!h) throw std::bad_alloc();
        h();
    }
}
}  // namespace

void* operator new(std::size_t n) { return allocate(n); }
void* operator new[](std::size_t n) { return allocate(n); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
    try {
        return allocate(n);
    } catch (...) {
        return nullptr;
    }
}
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept {
    try {
        return allocate(n);
    } catch (...) {
        return nullptr;
    }
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
