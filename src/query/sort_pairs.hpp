// SPDX-License-Identifier: MIT
// Internal: the order both queries return their pairs in.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

namespace hbvh::detail {

/// Sorts `pairs` ascending, by first then second (std::sort's order for pairs), where every first is below
/// `first_count` and every second below `second_count` (the two trees' primitive counts). Overlapping objects
/// report tens to thousands of pairs per query, and std::sort on the pairs took 2-9 % of the tandem traversal's
/// time on partly overlapping objects: pairs that are many for the counts are sorted by two counting passes (by
/// second, then stably by first), the others by std::sort on each pair packed into one 64-bit key (one comparison
/// instead of two).
void sort_many_pairs(std::vector<std::pair<std::uint32_t, std::uint32_t>>& pairs, std::uint32_t first_count,
                     std::uint32_t second_count);

/// sort_many_pairs, with the queries that report no pair or one (every near miss) spared the call.
inline void sort_pairs(std::vector<std::pair<std::uint32_t, std::uint32_t>>& pairs, std::uint32_t first_count,
                       std::uint32_t second_count) {
    if (pairs.size() > 1) sort_many_pairs(pairs, first_count, second_count);
}

}  // namespace hbvh::detail
