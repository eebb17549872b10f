#pragma once
// NONSEP_TEST_ADDRESS_SANITIZER is 1 in a build with AddressSanitizer, under GCC (__SANITIZE_ADDRESS__) and clang
// (__has_feature), for the few tests whose expectations differ there (crash statuses, address-space limits).
#if defined(__SANITIZE_ADDRESS__)
#define NONSEP_TEST_ADDRESS_SANITIZER 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define NONSEP_TEST_ADDRESS_SANITIZER 1
#endif
#endif
