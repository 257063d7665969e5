// SPDX-License-Identifier: MIT
// Internal: functions compiled twice, for plain x86-64 and for AVX2, the copy picked at load time.
#pragma once

/// The portable build targets x86-64 without AVX, where a loop over doubles runs two lanes at a time. A hot
/// loop marked HBVH_WIDE_CLONES also comes in an AVX2 copy (four lanes), which the loader picks where the
/// processor has it. Only loops whose every lane does the same operations in the same order are marked, so
/// both copies give the same bits and a tree does not depend on the machine that built it.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define HBVH_WIDE_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define HBVH_WIDE_CLONES
#endif
