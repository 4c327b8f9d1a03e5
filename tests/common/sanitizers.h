#pragma once
// NAVE_TEST_UNDER_ASAN is 1 in a build with AddressSanitizer, by GCC (__SANITIZE_ADDRESS__) or by
// clang (__has_feature(address_sanitizer)), for the tests that measure what ASan changes (memory
// peaks, address-space limits).

#if defined(__SANITIZE_ADDRESS__)
#define NAVE_TEST_UNDER_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define NAVE_TEST_UNDER_ASAN 1
#endif
#endif
#ifndef NAVE_TEST_UNDER_ASAN
#define NAVE_TEST_UNDER_ASAN 0
#endif
