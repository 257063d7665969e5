// SPDX-License-Identifier: MIT
// The subset DP behind build_optimal and treelet refinement (docs/solver.md §2).
//
// Eq. 2 charges an inner node over S with k children k·vol(S). So with best(S) the cheapest subtree over
// S (0 for a single primitive) and P_k(S) the cheapest sum of best() over a partition of S into exactly k
// blocks,
//     best(S)  = min_{k >= 2} k·vol(S) + P_k(S)
//     P_1(S)   = best(S)
//     P_k(S)   = min over blocks B with min(S) ∈ B ⊊ S of best(B) + P_{k-1}(S \ B)     (k >= 2)
// Fixing the block that holds the lowest element enumerates every partition exactly once. Pairs (S, B)
// number (3^n - 1)/2, each with an inner loop over k <= |S \ B|, so the time is O(n·3^n) worst case and
// about (n/3)·3^n/2 in practice; memory is n·2^n doubles. A subset reads only its proper subsets, which
// are smaller integers and have fewer members.
#include "optimal_plan.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <limits>

#include "../simd/wide_clones.hpp"
#include "hbvh/assert.hpp"

namespace hbvh {
namespace {

constexpr double infinite_cost = std::numeric_limits<double>::infinity();

/// std::popcount inline: the portable build targets x86-64 without the popcnt instruction, where std::popcount
/// is a library call, and the inner loops below take one per pair of subsets (7 % of the cannon's build).
constexpr std::uint32_t member_count(std::uint32_t mask) {
    mask = mask - ((mask >> 1) & 0x55555555u);
    mask = (mask & 0x33333333u) + ((mask >> 2) & 0x33333333u);
    mask = (mask + (mask >> 4)) & 0x0F0F0F0Fu;
    return (mask * 0x01010101u) >> 24;
}
static_assert(member_count(0) == 0 && member_count(0xFFFFFFFFu) == 32 && member_count(0x80000101u) == 3);

// The two hot loops below come in an AVX2 copy (simd/wide_clones.hpp): min and add on four doubles at once
// instead of two, the same operations on every element, so the tables are bit for bit the same either way.

/// From this many primitives on, the subsets of one size are solved in parallel (below, a task costs more
/// than the work: treelets solve DPs of a few units).
constexpr std::uint32_t parallel_from = 12;

/// best(S), P_k(S) and argmin k for one subset S, from the entries of its proper subsets.
HBVH_WIDE_CLONES void solve_subset(detail::SubsetTables& t, std::span<const double> volume, std::uint32_t s) {
    double* row = t.row(s);
    const std::uint32_t size = member_count(s);
    if (size == 1) {
        row[0] = 0.0;  // a single primitive is a leaf: no cost
        return;
    }
    // P_k(S), k >= 2: the block B holding the lowest element, the rest R partitioned into k-1 blocks.
    const std::uint32_t low = s & (~s + 1u);
    const std::uint32_t rest = s ^ low;
    for (std::uint32_t sub = (rest - 1u) & rest;; sub = (sub - 1u) & rest) {
        const std::uint32_t block = low | sub;
        const std::uint32_t remainder = s ^ block;
        const double block_cost = t.best[block];
        const double* from = t.row(remainder);
        const std::uint32_t remainder_size = member_count(remainder);
        for (std::uint32_t k = 0; k < remainder_size; ++k) row[k + 1] = std::min(row[k + 1], block_cost + from[k]);
        if (sub == 0) break;
    }
    // best(S) = min over k >= 2 of k·vol(S) + P_k(S); the first (smallest) k wins ties. Two children stand until
    // a candidate is cheaper, so that S has a valid split even where every price is infinite (volumes that
    // overflow far from the origin): with none recorded, plan_of queued S as its own child without end.
    const double w = volume[s];
    double best = infinite_cost;
    std::uint8_t arg = 2;
    for (std::uint32_t k = 2; k <= size; ++k) {
        const double candidate = static_cast<double>(k) * w + row[k - 1];
        if (candidate < best) {
            best = candidate;
            arg = static_cast<std::uint8_t>(k);
        }
    }
    t.best[s] = best;
    t.children[s] = arg;
    row[0] = best;
}

/// j as a double, j = 0, 1, 2, ...: a parent with S and j + 1 blocks of R as children has j children more than two.
constexpr std::array<double, optimal_hard_limit> extra_children = [] {
    std::array<double, optimal_hard_limit> out{};
    for (std::size_t j = 0; j < out.size(); ++j) out[j] = static_cast<double>(j);
    return out;
}();

/// outside(S), pulled from the larger sets. S's parent Q has S and a partition of R = Q \ S into j blocks as
/// its j + 1 children, so
///     outside(S) = min over R != {} disjoint from S, j = 1..|R| of outside(S | R) + (j+1)·vol(S | R) + P_j(R).
HBVH_WIDE_CLONES double outside_of(const detail::SubsetTables& t, std::span<const double> volume,
                                   std::span<const double> outside, std::uint32_t s) {
    const std::uint32_t others = ((1u << t.count) - 1u) ^ s;
    // The least so far per j, in independent lanes the compiler vectorises (one running minimum would chain
    // every term).
    std::array<double, optimal_hard_limit> least_by_blocks;
    least_by_blocks.fill(infinite_cost);
    for (std::uint32_t r = others; r != 0; r = (r - 1u) & others) {
        const std::uint32_t q = s | r;
        const double w = volume[q];
        const double two_children = outside[q] + 2.0 * w;
        const double* parts = t.row(r);
        const std::uint32_t r_size = member_count(r);
        for (std::uint32_t j = 0; j < r_size; ++j)
            least_by_blocks[j] = std::min(least_by_blocks[j], two_children + extra_children[j] * w + parts[j]);
    }
    return *std::min_element(least_by_blocks.begin(), least_by_blocks.end());
}

/// Splits S into the k blocks that realise P_k(S): the same sums as solve_subset, so equality is exact.
std::vector<std::uint32_t> blocks_of(const detail::SubsetTables& t, std::uint32_t s, std::uint32_t k) {
    std::vector<std::uint32_t> blocks;
    while (k > 1) {
        const double target = t.row(s)[k - 1];
        const std::uint32_t low = s & (~s + 1u);
        const std::uint32_t rest = s ^ low;
        std::uint32_t chosen = 0;
        for (std::uint32_t sub = (rest - 1u) & rest;; sub = (sub - 1u) & rest) {
            const std::uint32_t block = low | sub;
            if (member_count(s ^ block) >= k - 1 && t.best[block] + t.row(s ^ block)[k - 2] == target) {
                chosen = block;
                break;
            }
            if (sub == 0) break;
        }
        // No block matches the target only where the prices are not numbers (NaN from inf - inf): any split
        // of S is then as good as another, and the lowest element alone keeps every block a proper subset.
        if (chosen == 0) chosen = low;
        blocks.push_back(chosen);
        s ^= chosen;
        --k;
    }
    blocks.push_back(s);
    return blocks;
}

}  // namespace

namespace detail {

std::vector<std::vector<std::uint32_t>> masks_by_size(std::uint32_t count) {
    std::vector<std::vector<std::uint32_t>> out(count + 1);
    for (std::uint32_t mask = 1; mask < (1u << count); ++mask) out[member_count(mask)].push_back(mask);
    return out;
}

SubsetTables solve_subsets(std::uint32_t count, std::span<const double> volume) {
    HBVH_ASSERT(count >= 2 && count <= optimal_hard_limit);
    HBVH_ASSERT(volume.size() == (std::size_t{1} << count));
    SubsetTables t;
    t.count = count;
    const std::uint32_t subsets = 1u << count;
    t.best.assign(subsets, 0.0);
    t.parts.assign(std::size_t{subsets} * count, infinite_cost);
    t.children.assign(subsets, 0);
    if (count < parallel_from) {  // increasing order lists every proper subset before its superset
        for (std::uint32_t s = 1; s < subsets; ++s) solve_subset(t, volume, s);
        return t;
    }
    // A size at a time: each entry is the same sums in the same order as in the serial loop.
    const std::vector<std::vector<std::uint32_t>> by_size = masks_by_size(count);
    for (std::uint32_t size = 1; size <= count; ++size)
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, by_size[size].size(), 16),
                          [&](const tbb::blocked_range<std::size_t>& range) {
                              for (std::size_t j = range.begin(); j != range.end(); ++j)
                                  solve_subset(t, volume, by_size[size][j]);
                          });
    return t;
}

OptimalPlan plan_of(const SubsetTables& t) {
    OptimalPlan plan;
    const std::uint32_t full = (1u << t.count) - 1u;
    plan.cost = t.best[full];
    // Breadth-first, so parents precede children.
    std::vector<std::uint32_t> queue{full};
    for (std::size_t i = 0; i < queue.size(); ++i) {
        const std::uint32_t s = queue[i];
        OptimalGroup group{s, blocks_of(t, s, t.children[s])};
        std::sort(group.children.begin(), group.children.end());
        for (std::uint32_t child : group.children)
            if (member_count(child) > 1) queue.push_back(child);
        plan.groups.push_back(std::move(group));
    }
    return plan;
}

std::vector<double> cost_outside(const SubsetTables& t, std::span<const double> volume) {
    const std::uint32_t full = (1u << t.count) - 1u;
    std::vector<double> outside(std::size_t{full} + 1, infinite_cost);
    outside[full] = 0.0;
    // Each entry reads only larger sets' (its possible parents): a size at a time from the largest.
    const std::vector<std::vector<std::uint32_t>> by_size = masks_by_size(t.count);
    for (std::uint32_t size = t.count - 1; size >= 2; --size)
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, by_size[size].size(), 16),
                          [&](const tbb::blocked_range<std::size_t>& range) {
                              for (std::size_t j = range.begin(); j != range.end(); ++j)
                                  outside[by_size[size][j]] = outside_of(t, volume, outside, by_size[size][j]);
                          });
    return outside;
}

}  // namespace detail

OptimalPlan solve_optimal_hierarchy(std::uint32_t count, std::span<const double> subset_volume) {
    HBVH_ASSERT(count >= 1 && count <= optimal_hard_limit);
    HBVH_ASSERT(subset_volume.size() == (std::size_t{1} << count));
    if (count == 1) return {};
    return detail::plan_of(detail::solve_subsets(count, subset_volume));
}

}  // namespace hbvh
