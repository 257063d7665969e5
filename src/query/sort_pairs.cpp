// SPDX-License-Identifier: MIT
#include "sort_pairs.hpp"

#include <algorithm>

#include "hbvh/assert.hpp"
#include "../memory/thread_scratch.hpp"

namespace hbvh::detail {
namespace pair_order {  // named, so that a unity build's other anonymous helpers cannot collide

using Pair = std::pair<std::uint32_t, std::uint32_t>;

/// The counting passes pay for their count arrays (first_count + second_count entries) when these hold at most this
/// many entries per pair, and there are at least counting_min_pairs pairs. Measured on random pairs (std::sort on
/// keys against the two passes, µs): 100 pairs over 1 000 x 1 000 indices 0.70 / 1.56, 200 pairs 1.13 / 1.10,
/// 400 pairs 2.92 / 1.56, 828 pairs 6.80 / 2.68; 738 pairs over 100 x 100 5.91 / 2.34; 33 pairs over 21 x 21
/// 0.11 / 0.15, 64 over 100 x 100 0.40 / 0.35 (std::sort on the pairs themselves: 0.70-1.8x the keys' time).
constexpr std::size_t counting_indices_per_pair = 10;
constexpr std::size_t counting_min_pairs = 64;
/// Below this many, std::sort on the pairs themselves: packing them costs what it saves (16 pairs: 0.087 µs
/// unpacked, 0.069 packed; 8 pairs: the same).
constexpr std::size_t key_min_pairs = 16;

/// Stable counting sort of `from` into `to` by the index `index_of` gives each pair (all below `count`).
template <class IndexOf>
void counting_pass(const std::vector<Pair>& from, std::vector<Pair>& to, std::uint32_t count, IndexOf index_of,
                   std::vector<std::uint32_t>& starts) {
    starts.assign(std::size_t{count} + 1, 0);
    for (const Pair& p : from) {
        HBVH_ASSERT(index_of(p) < count);
        ++starts[index_of(p) + 1];
    }
    for (std::size_t i = 1; i < starts.size(); ++i) starts[i] += starts[i - 1];
    to.resize(from.size());
    for (const Pair& p : from) to[starts[index_of(p)]++] = p;
}

}  // namespace pair_order

void sort_many_pairs(std::vector<pair_order::Pair>& pairs, std::uint32_t first_count, std::uint32_t second_count) {
    using namespace pair_order;
    if (pairs.size() < key_min_pairs) {
        std::sort(pairs.begin(), pairs.end());
        return;
    }
    const bool counting = pairs.size() >= counting_min_pairs &&
                          pairs.size() * counting_indices_per_pair >= std::size_t{first_count} + second_count;
    if (counting) {
        // Per thread and kept (memory/thread_scratch.hpp), so that warm queries allocate nothing.
        thread_local std::vector<Pair> by_second;
        thread_local std::vector<std::uint32_t> starts;
        const ReleaseIfLarge release(by_second, starts);
        counting_pass(pairs, by_second, second_count, [](const Pair& p) { return p.second; }, starts);
        counting_pass(by_second, pairs, first_count, [](const Pair& p) { return p.first; }, starts);
        return;
    }
    thread_local std::vector<std::uint64_t> keys;
    const ReleaseIfLarge release(keys);
    keys.resize(pairs.size());
    for (std::size_t i = 0; i < pairs.size(); ++i)
        keys[i] = (std::uint64_t{pairs[i].first} << 32) | pairs[i].second;
    std::sort(keys.begin(), keys.end());
    for (std::size_t i = 0; i < pairs.size(); ++i)
        pairs[i] = {static_cast<std::uint32_t>(keys[i] >> 32), static_cast<std::uint32_t>(keys[i])};
}

}  // namespace hbvh::detail
