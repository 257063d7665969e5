// SPDX-License-Identifier: MIT
// HBVH_ASSERT: checks of invariants (bugs in calling code), on in Debug builds and tests.
#pragma once

#include <cstdio>
#include <cstdlib>

#if !defined(NDEBUG) || defined(HBVH_ENABLE_ASSERTS)
#define HBVH_ASSERT(condition)                                                               \
    do {                                                                                      \
        if (!(condition)) {                                                                   \
            std::fprintf(stderr, "%s:%d: assertion failed: %s\n", __FILE__, __LINE__, #condition); \
            std::abort();                                                                     \
        }                                                                                     \
    } while (false)
#else
#define HBVH_ASSERT(condition) ((void)sizeof(condition))
#endif
