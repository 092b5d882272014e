// Whether this build runs under AddressSanitizer: GCC defines __SANITIZE_ADDRESS__, clang
// answers __has_feature(address_sanitizer). Tests that limit address space or count on speed
// adapt to it (ASan reserves terabytes of shadow memory and runs several times slower).
#pragma once

#if defined(__SANITIZE_ADDRESS__)
#define CROWDDB_TEST_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define CROWDDB_TEST_ASAN 1
#endif
#endif
