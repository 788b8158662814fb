#pragma once

// DYNID_UNDER_ASAN is 1 in an AddressSanitizer build: gcc defines __SANITIZE_ADDRESS__, clang
// answers __has_feature(address_sanitizer) instead.
#if defined(__SANITIZE_ADDRESS__)
#define DYNID_UNDER_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define DYNID_UNDER_ASAN 1
#endif
#endif
#ifndef DYNID_UNDER_ASAN
#define DYNID_UNDER_ASAN 0
#endif
