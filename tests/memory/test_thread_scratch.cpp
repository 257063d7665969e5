// SPDX-License-Identifier: MIT
// src/memory/thread_scratch.hpp: a scratch array keeps its memory while it is small and gives it back once a call
// has grown it past thread_scratch_keep_bytes, however the scope ends.
#include <gtest/gtest.h>

#include <cstdint>
#include <stdexcept>
#include <vector>

#include "memory/thread_scratch.hpp"

namespace hbvh {
namespace {

using detail::ReleaseIfLarge;
using detail::thread_scratch_keep_bytes;

TEST(ThreadScratch, SmallArraysKeepTheirMemoryAndLargeOnesGiveItBack) {
    std::vector<double> small;
    std::vector<std::uint32_t> large;
    {
        const ReleaseIfLarge release(small, large);
        small.resize(100);
        large.resize(thread_scratch_keep_bytes / sizeof(std::uint32_t) + 1);
    }
    EXPECT_GE(small.capacity(), 100u);  // kept for the next call
    EXPECT_EQ(large.capacity(), 0u);    // given back

    // Exactly at the limit is still kept.
    std::vector<char> at_limit(thread_scratch_keep_bytes);
    at_limit.shrink_to_fit();
    ASSERT_EQ(at_limit.capacity(), thread_scratch_keep_bytes);
    { const ReleaseIfLarge release(at_limit); }
    EXPECT_EQ(at_limit.capacity(), thread_scratch_keep_bytes);
}

TEST(ThreadScratch, LargeArraysAreGivenBackWhenTheScopeEndsByAnException) {
    std::vector<double> large;
    const auto grow_and_throw = [&] {
        const ReleaseIfLarge release(large);
        large.resize(thread_scratch_keep_bytes);  // 8x the limit in bytes
        throw std::runtime_error("stop");
    };
    EXPECT_THROW(grow_and_throw(), std::runtime_error);
    EXPECT_EQ(large.capacity(), 0u);
}

}  // namespace
}  // namespace hbvh
