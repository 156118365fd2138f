// kfd::alloc_limit: the allocation functions MRPT's deserialisers reach, with
// kfd::allocationLimit() enforced (see kfd/mrpt/allocation_limit.h):
//
// - the global operator new / new[] (plain, nothrow, and the C++17 aligned forms), with their
//   deletes: std::string, std::vector and every object MRPT creates;
// - mrpt::aligned_malloc (MRPT 2.5.8, libmrpt-core): the allocator of mrpt::aligned_std_vector
//   (CObservation2DRangeScan's ranges, validity and intensity arrays) and of MRPT's dynamic
//   matrices. MRPT's own version forwards to aligned_alloc and returns its null on failure,
//   which aligned_allocator_cpp11 hands to std::vector unchecked (a segfault under a memory
//   limit); this one throws std::bad_alloc instead, as an allocator must. libmrpt-obs and the
//   other MRPT libraries call it through their PLT, so the executable's definition (exported
//   because those libraries reference it) takes their calls; mrpt::aligned_free stays MRPT's
//   (free(), which matches aligned_alloc).
//
// malloc-based like libstdc++'s own; each allocation function is replaced with its
// deallocation functions, so that each pointer is freed by the allocator that made it (the
// sanitizer runtimes, which intercept malloc, aligned_alloc and free, check that pairing).
#include <mrpt/core/aligned_allocator.h>

#include <cstdint>
#include <cstdlib>
#include <new>

#include "kfd/mrpt/allocation_limit.h"

namespace {

void checkLimit(std::size_t n) {
    if (n > kfd::allocationLimit()) throw std::bad_alloc();
}

// `alloc` until it succeeds or no new-handler is left ([new.delete.single]).
template <class Alloc>
void* withNewHandler(Alloc alloc) {
    for (;;) {
        if (void* p = alloc()) return p;
        std::new_handler h = std::get_new_handler();
        if (!h) throw std::bad_alloc();
        h();
    }
}

void* allocate(std::size_t n) {
    checkLimit(n);
    return withNewHandler([n] { return std::malloc(n == 0 ? 1 : n); });
}

void* allocateAligned(std::size_t n, std::size_t alignment) {
    checkLimit(n);
    if (alignment < sizeof(void*)) alignment = sizeof(void*);  // posix_memalign's minimum
    return withNewHandler([n, alignment]() -> void* {
        void* p = nullptr;
        return posix_memalign(&p, alignment, n == 0 ? 1 : n) == 0 ? p : nullptr;
    });
}

template <class F>
void* nothrow(F f) noexcept {
    try {
        return f();
    } catch (...) {
        return nullptr;
    }
}

}  // namespace

void* operator new(std::size_t n) { return allocate(n); }
void* operator new[](std::size_t n) { return allocate(n); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
    return nothrow([n] { return allocate(n); });
}
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept {
    return nothrow([n] { return allocate(n); });
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }

// Over-aligned types (alignof > 16: MRPT's fixed-size Eigen members under AVX), e.g. a
// std::vector<mrpt::poses::CPose3D> read from a file.
void* operator new(std::size_t n, std::align_val_t a) {
    return allocateAligned(n, static_cast<std::size_t>(a));
}
void* operator new[](std::size_t n, std::align_val_t a) {
    return allocateAligned(n, static_cast<std::size_t>(a));
}
void* operator new(std::size_t n, std::align_val_t a, const std::nothrow_t&) noexcept {
    return nothrow([n, a] { return allocateAligned(n, static_cast<std::size_t>(a)); });
}
void* operator new[](std::size_t n, std::align_val_t a, const std::nothrow_t&) noexcept {
    return nothrow([n, a] { return allocateAligned(n, static_cast<std::size_t>(a)); });
}
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }

// MRPT's own, but a failure is std::bad_alloc rather than a null pointer. MRPT's rounding is
// kept (the size up to a multiple of the alignment, as aligned_alloc wanted before C11's DR
// 460), without its wrap-around near SIZE_MAX.
void* mrpt::aligned_malloc(std::size_t size, std::size_t alignment) {
    checkLimit(size);
    if (alignment != 0 && size % alignment != 0) {
        if (size > SIZE_MAX - alignment) throw std::bad_alloc();
        size = (size / alignment + 1) * alignment;
    }
    void* p = std::aligned_alloc(alignment, size);
    if (!p && size != 0) throw std::bad_alloc();
    return p;
}
