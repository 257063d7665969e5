// SPDX-License-Identifier: MIT
// The subset DP behind build_optimal (docs/solver.md §2).
//
// Eq. 2 charges an inner node over S with k children k·vol(S). So with best(S) the cheapest subtree over
// S (0 for a single primitive) and P_k(S) the cheapest sum of best() over a partition of S into exactly k
// blocks,
//     best(S)  = min_{k >= 2} k·vol(S) + P_k(S)
//     P_1(S)   = best(S)
//     P_k(S)   = min over blocks B with min(S) ∈ B ⊊ S of best(B) + P_{k-1}(S \ B)     (k >= 2)
// Fixing the block that holds the lowest element enumerates every partition exactly once. Pairs (S, B)
// number (3^n - 1)/2, each with an inner loop over k <= |S \ B|, so the time is O(n·3^n) worst case and
// about (n/3)·3^n/2 in practice; memory is n·2^n doubles. Subsets are visited in increasing integer
// order, which lists every proper subset before its superset.
#include "hbvh/builders/optimal.hpp"
#include "optimal_plan.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>

#include "guarded_build.hpp"
#include "hbvh/assert.hpp"
#include "hbvh/builders/bnb_exact.hpp"
#include "hbvh/fit/fit.hpp"

namespace hbvh {
namespace {

constexpr double infinite_cost = std::numeric_limits<double>::infinity();

/// The tables of the DP.
struct Tables {
    std::uint32_t count = 0;
    std::vector<double> best;           // best(S)
    std::vector<double> parts;          // P_k(S) at parts[S * count + k - 1], k = 1..|S|
    std::vector<std::uint8_t> children; // argmin k of best(S)

    [[nodiscard]] const double* row(std::uint32_t s) const { return parts.data() + std::size_t{s} * count; }
    [[nodiscard]] double* row(std::uint32_t s) { return parts.data() + std::size_t{s} * count; }
};

Tables run_dp(std::uint32_t count, std::span<const double> volume) {
    Tables t;
    t.count = count;
    const std::uint32_t subsets = 1u << count;
    t.best.assign(subsets, 0.0);
    t.parts.assign(std::size_t{subsets} * count, infinite_cost);
    t.children.assign(subsets, 0);
    for (std::uint32_t s = 1; s < subsets; ++s) {
        double* row = t.row(s);
        const auto size = static_cast<std::uint32_t>(std::popcount(s));
        if (size == 1) {
            row[0] = 0.0;  // a single primitive is a leaf: no cost
            continue;
        }
        // P_k(S), k >= 2: the block B holding the lowest element, the rest R partitioned into k-1 blocks.
        const std::uint32_t low = s & (~s + 1u);
        const std::uint32_t rest = s ^ low;
        for (std::uint32_t sub = (rest - 1u) & rest;; sub = (sub - 1u) & rest) {
            const std::uint32_t block = low | sub;
            const std::uint32_t remainder = s ^ block;
            const double block_cost = t.best[block];
            const double* from = t.row(remainder);
            const auto remainder_size = static_cast<std::uint32_t>(std::popcount(remainder));
            for (std::uint32_t k = 0; k < remainder_size; ++k) row[k + 1] = std::min(row[k + 1], block_cost + from[k]);
            if (sub == 0) break;
        }
        // best(S) = min over k >= 2 of k·vol(S) + P_k(S); the first (smallest) k wins ties.
        const double w = volume[s];
        double best = infinite_cost;
        std::uint8_t arg = 0;
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
    return t;
}

/// Splits S into the k blocks that realise P_k(S): the same sums as run_dp, so equality is exact.
std::vector<std::uint32_t> blocks_of(const Tables& t, std::uint32_t s, std::uint32_t k) {
    std::vector<std::uint32_t> blocks;
    while (k > 1) {
        const double target = t.row(s)[k - 1];
        const std::uint32_t low = s & (~s + 1u);
        const std::uint32_t rest = s ^ low;
        std::uint32_t chosen = 0;
        for (std::uint32_t sub = (rest - 1u) & rest;; sub = (sub - 1u) & rest) {
            const std::uint32_t block = low | sub;
            if (std::popcount(s ^ block) >= static_cast<int>(k - 1) && t.best[block] + t.row(s ^ block)[k - 2] == target) {
                chosen = block;
                break;
            }
            if (sub == 0) break;
        }
        HBVH_ASSERT(chosen != 0);
        blocks.push_back(chosen);
        s ^= chosen;
        --k;
    }
    blocks.push_back(s);
    return blocks;
}

}  // namespace

OptimalPlan solve_optimal_hierarchy(std::uint32_t count, std::span<const double> subset_volume) {
    HBVH_ASSERT(count >= 1 && count <= optimal_hard_limit);
    HBVH_ASSERT(subset_volume.size() == (std::size_t{1} << count));
    OptimalPlan plan;
    if (count == 1) return plan;
    const Tables t = run_dp(count, subset_volume);
    const std::uint32_t full = (1u << count) - 1u;
    plan.cost = t.best[full];
    // Breadth-first, so parents precede children.
    std::vector<std::uint32_t> queue{full};
    for (std::size_t i = 0; i < queue.size(); ++i) {
        const std::uint32_t s = queue[i];
        OptimalGroup group{s, blocks_of(t, s, t.children[s])};
        std::sort(group.children.begin(), group.children.end());
        for (std::uint32_t child : group.children)
            if (std::popcount(child) > 1) queue.push_back(child);
        plan.groups.push_back(std::move(group));
    }
    return plan;
}

namespace {
Result<Bvh> optimal_tree(std::span<const Primitive> primitives, const BuildContext& context, std::uint32_t limit,
                         const detail::Checkpoint& checkpoint);
}  // namespace

Result<Bvh> build_optimal(std::span<const Primitive> primitives, const BuildContext& context,
                          const OptimalOptions& options) {
    const std::uint32_t limit = std::min(options.max_primitives, optimal_hard_limit);
    if (primitives.size() > limit && options.fall_back) {
        // Documented refusal of the DP, but a tree all the same (docs/solver.md §2).
        Result<Bvh> fallback = build_bnb_exact(primitives, context);
        if (fallback && context.report != nullptr) {
            context.report->lower_bound = 0.0;
            context.report->built_by = "bnb-exact";
            context.report->notes.push_back("optimal: " + std::to_string(primitives.size()) +
                                            " primitives exceed the limit of " + std::to_string(limit) +
                                            "; built bnb-exact instead (not proven optimal)");
        }
        return fallback;
    }
    const double subsets = std::ldexp(1.0, static_cast<int>(std::min<std::size_t>(primitives.size(), 30)));
    return detail::guarded_build(primitives, context, "optimal", subsets, [&](const detail::Checkpoint& checkpoint) {
        return optimal_tree(primitives, context, limit, checkpoint);
    });
}

namespace {
Result<Bvh> optimal_tree(std::span<const Primitive> primitives, const BuildContext& context, std::uint32_t limit,
                         const detail::Checkpoint& checkpoint) {
    const auto start = std::chrono::steady_clock::now();
    const VolumePolicy& policy = context.policy;
    BuildReport* report = context.report;
    if (primitives.size() > limit)
        return Error{"the optimal builder handles at most " + std::to_string(limit) + " primitives, got " +
                     std::to_string(primitives.size()) + " (its subset DP is exponential; see docs/solver.md)"};
    const auto count = static_cast<std::uint32_t>(primitives.size());
    TreeAssembler assembler(primitives);
    std::vector<std::uint32_t> leaves(count);
    for (std::uint32_t i = 0; i < count; ++i) leaves[i] = assembler.add_leaf(i);
    if (count == 1) return std::move(assembler).finish(leaves.front());

    // Stage 1: the weighted volume of fit_best over every subset of two or more primitives. Each entry
    // depends on its subset only, so the parallel loop is deterministic for any thread count.
    auto fit_subset = [&](std::uint32_t mask) {
        FitInput input;
        for (std::uint32_t i = 0; i < count; ++i)
            if (mask >> i & 1u) input.add(primitives[i].volume);
        return fit_best(input.spheres, policy, input.hint_axes);
    };
    std::vector<double> volume(std::size_t{1} << count, 0.0);
    tbb::parallel_for(tbb::blocked_range<std::uint32_t>(1, 1u << count, 512),
                      [&](const tbb::blocked_range<std::uint32_t>& range) {
                          checkpoint.step(range.begin());  // blocks in any order: progress is approximate
                          for (std::uint32_t mask = range.begin(); mask != range.end(); ++mask)
                              if (std::popcount(mask) > 1) volume[mask] = policy.weighted_volume(fit_subset(mask));
                      });

    checkpoint.step(static_cast<double>(1u << count));
    // Stage 2: the DP, then the tree it chose (children before parents for the assembler).
    const OptimalPlan plan = solve_optimal_hierarchy(count, volume);
    std::vector<std::uint32_t> id_of(std::size_t{1} << count, 0);
    for (std::uint32_t i = 0; i < count; ++i) id_of[1u << i] = leaves[i];
    for (auto it = plan.groups.rbegin(); it != plan.groups.rend(); ++it) {
        std::vector<std::uint32_t> children;
        for (std::uint32_t child : it->children) children.push_back(id_of[child]);
        id_of[it->covered] = assembler.add_group(children, fit_subset(it->covered));
    }
    if (report != nullptr) {
        LevelReport level;
        level.nodes = count;
        level.groups = static_cast<std::uint32_t>(plan.groups.size());
        level.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        report->levels.push_back(level);
        report->lower_bound = plan.cost;
        report->notes.push_back("optimal: subset DP over " + std::to_string((1u << count) - count - 1) + " fitted subsets");
    }
    return std::move(assembler).finish(id_of[(1u << count) - 1u]);
}
}  // namespace

}  // namespace hbvh
