// SPDX-License-Identifier: MIT
// The queries' pair order (src/query/sort_pairs.hpp) against std::sort, in each of its three regimes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <utility>
#include <vector>

#include "query/sort_pairs.hpp"

namespace hbvh {
namespace {

using Pairs = std::vector<std::pair<std::uint32_t, std::uint32_t>>;

/// `count` pairs with indices below `first_count` and `second_count`, distinct (as a query reports them) unless
/// `repeats`, in the order a traversal might give: runs grouped by subtree, then shuffled in part.
Pairs random_pairs(std::mt19937& rng, std::size_t count, std::uint32_t first_count, std::uint32_t second_count,
                   bool repeats) {
    Pairs pairs;
    while (pairs.size() < count) {
        const std::pair<std::uint32_t, std::uint32_t> p{static_cast<std::uint32_t>(rng() % first_count),
                                                        static_cast<std::uint32_t>(rng() % second_count)};
        if (repeats || std::find(pairs.begin(), pairs.end(), p) == pairs.end()) pairs.push_back(p);
    }
    std::sort(pairs.begin(), pairs.end(), [](const auto& a, const auto& b) { return a.second < b.second; });
    std::shuffle(pairs.begin(), pairs.begin() + static_cast<std::ptrdiff_t>(pairs.size() / 2), rng);
    return pairs;
}

TEST(SortPairs, MatchesStdSortInEveryRegime) {
    std::mt19937 rng(7);
    // Counts chosen to fall on each side of each switch: below 16 (std::sort on the pairs), keys (few pairs for
    // the index counts), counting passes (many), and the extremes of the index ranges.
    struct Case { std::size_t count; std::uint32_t first_count, second_count; };
    const Case cases[] = {{0, 5, 5},      {1, 5, 5},        {2, 3, 3},       {15, 40, 40},   {16, 40, 40},
                          {63, 10, 10},   {64, 10, 10},     {64, 1000, 1000}, {199, 1000, 1000}, {200, 1000, 1000},
                          {828, 1000, 1000}, {700, 100, 100}, {300, 1, 400},   {300, 400, 1},  {2000, 7, 3000},
                          {1500, 50000, 40}};
    for (const Case& c : cases)
        for (const bool repeats : {false, true}) {
            if (!repeats && c.count > std::size_t{c.first_count} * c.second_count) continue;
            Pairs pairs = random_pairs(rng, c.count, c.first_count, c.second_count, repeats);
            Pairs expected = pairs;
            std::sort(expected.begin(), expected.end());
            detail::sort_pairs(pairs, c.first_count, c.second_count);
            EXPECT_EQ(pairs, expected) << c.count << " pairs over " << c.first_count << " x " << c.second_count
                                       << (repeats ? " with repeats" : "");
        }
}

TEST(SortPairs, LargestIndicesKeepTheirBits) {
    // Packing into 64-bit keys must not lose the high bits of either index.
    Pairs pairs;
    for (std::uint32_t i = 0; i < 40; ++i) pairs.emplace_back(0xFFFFFFFEu - i % 3, 0x80000000u + (i * 7919u) % 11u);
    Pairs expected = pairs;
    std::sort(expected.begin(), expected.end());
    detail::sort_pairs(pairs, 0xFFFFFFFFu, 0xFFFFFFFFu);
    EXPECT_EQ(pairs, expected);
}

}  // namespace
}  // namespace hbvh
