// Whether the tests run under AddressSanitizer (the CI's sanitizer job): it reserves terabytes
// of address space and keeps freed memory in a quarantine, so limits on address space or on
// resident memory hold only without it.
#pragma once

namespace kfd::test {

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kAsan = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kAsan = true;
#else
constexpr bool kAsan = false;
#endif
#else
constexpr bool kAsan = false;
#endif

}  // namespace kfd::test
