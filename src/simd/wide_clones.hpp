// SPDX-License-Identifier: MIT
// Internal: functions compiled twice, for plain x86-64 and for AVX2, the copy picked at load time.
#pragma once

/// The portable build targets x86-64 without AVX, where a loop over doubles runs two lanes at a time. A hot
/// loop marked HBVH_WIDE_CLONES also comes in an AVX2 copy (four lanes), which the loader picks where the
/// processor has it. Only loops whose every lane does the same operations in the same order are marked, so
/// both copies give the same bits and a tree does not depend on the machine that built it.
///
/// Not under ThreadSanitizer (GCC defines __SANITIZE_THREAD__): the loader runs the clones' resolvers before TSan
/// is set up, and the instrumented resolver crashed every program at start-up (a user's review, 2026-12-08).
/// HBVH_NO_WIDE_CLONES turns them off for any other tool that cannot take them.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__SANITIZE_THREAD__) && \
    !defined(HBVH_NO_WIDE_CLONES)
#define HBVH_WIDE_CLONES __attribute__((target_clones("avx2", "default")))
#define HBVH_WIDE_CLONES_INLINED __attribute__((target_clones("avx2", "default"), flatten))
#else
#define HBVH_WIDE_CLONES
#define HBVH_WIDE_CLONES_INLINED
#endif

/// HBVH_WIDE_CLONES_INLINED also inlines into both copies every call it can (GCC's `flatten`): for an entry
/// point whose hot code lives in headers, such as a query (its node tests, leaf loops and traversal), so that
/// the AVX2 copy covers the whole of it and not just its first frame. Arithmetic is as written in either copy
/// (AVX2 without FMA contracts nothing), so both give the same bits.
