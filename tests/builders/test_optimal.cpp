// SPDX-License-Identifier: MIT
// build_optimal / solve_optimal_hierarchy against explicit enumeration of every hierarchy.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>

#include "support/test_helpers.hpp"
#include "hbvh/builders/build.hpp"
#include "builders/optimal_plan.hpp"
#include "hbvh/builders/optimal.hpp"
#include "hbvh/fit/fit.hpp"
#include "hbvh/scene/generate.hpp"
#include "hbvh/tree/stats.hpp"
#include "hbvh/tree/validate.hpp"

namespace hbvh {
namespace {

/// Every set partition of the bits of `s` into >= 1 blocks (recursive, block of the lowest bit first).
void partitions(std::uint32_t s, std::vector<std::uint32_t>& current, std::vector<std::vector<std::uint32_t>>& out) {
    if (s == 0) {
        out.push_back(current);
        return;
    }
    const std::uint32_t low = s & (~s + 1u);
    const std::uint32_t rest = s ^ low;
    for (std::uint32_t sub = rest;; sub = (sub - 1u) & rest) {
        current.push_back(low | sub);
        partitions(s ^ (low | sub), current, out);
        current.pop_back();
        if (sub == 0) break;
    }
}

/// The costs of ALL hierarchies over `s` (one entry per tree), enumerated explicitly.
const std::vector<double>& all_tree_costs(std::uint32_t s, const std::vector<double>& volume,
                                          std::map<std::uint32_t, std::vector<double>>& memo) {
    if (auto it = memo.find(s); it != memo.end()) return it->second;
    std::vector<double> costs;
    if (std::popcount(s) == 1) {
        costs.push_back(0.0);
    } else {
        std::vector<std::uint32_t> current;
        std::vector<std::vector<std::uint32_t>> all;
        partitions(s, current, all);
        for (const auto& blocks : all) {
            if (blocks.size() < 2) continue;
            // Cartesian product of the blocks' trees.
            std::vector<double> sums{static_cast<double>(blocks.size()) * volume[s]};
            for (std::uint32_t b : blocks) {
                const std::vector<double>& sub = all_tree_costs(b, volume, memo);
                std::vector<double> next;
                next.reserve(sums.size() * sub.size());
                for (double a : sums)
                    for (double c : sub) next.push_back(a + c);
                sums = std::move(next);
            }
            costs.insert(costs.end(), sums.begin(), sums.end());
        }
    }
    return memo.emplace(s, std::move(costs)).first->second;
}

/// Cost of a plan recomputed from its groups.
double plan_cost(const OptimalPlan& plan, const std::vector<double>& volume) {
    double sum = 0.0;
    for (const OptimalGroup& g : plan.groups) sum += static_cast<double>(g.children.size()) * volume[g.covered];
    return sum;
}

TEST(OptimalHierarchy, EnumeratorCountsSchroderTrees) {
    // Rooted trees with n labelled leaves and no unary nodes (Schröder's fourth problem, OEIS A000311).
    const std::vector<std::size_t> expected{1, 1, 4, 26, 236, 2752, 39208};
    for (std::uint32_t n = 1; n <= 7; ++n) {
        std::vector<double> volume(1u << n, 1.0);
        std::map<std::uint32_t, std::vector<double>> memo;
        EXPECT_EQ(all_tree_costs((1u << n) - 1u, volume, memo).size(), expected[n - 1]) << n;
    }
}

TEST(OptimalHierarchy, EqualsEnumerationOfAllTreesForRandomVolumeFunctions) {
    // Any set function, not only geometric ones: the DP must be optimal for all.
    SplitMix64 rng(4242);
    for (int trial = 0; trial < 300; ++trial) {
        const std::uint32_t n = 1 + static_cast<std::uint32_t>(rng.below(trial < 250 ? 6 : 7));
        std::vector<double> volume(1u << n, 0.0);
        for (std::uint32_t s = 1; s < (1u << n); ++s)
            volume[s] = rng.below(4) == 0 ? static_cast<double>(rng.below(3) + 1)  // ties
                                          : static_cast<double>(std::popcount(s)) * rng.uniform(0.2, 2.0);
        std::map<std::uint32_t, std::vector<double>> memo;
        const auto& costs = all_tree_costs((1u << n) - 1u, volume, memo);
        const double brute = *std::min_element(costs.begin(), costs.end());
        const OptimalPlan plan = solve_optimal_hierarchy(n, volume);
        EXPECT_NEAR(plan.cost, brute, 1e-9 * std::max(1.0, brute)) << "trial " << trial;
        EXPECT_NEAR(plan_cost(plan, volume), plan.cost, 1e-9 * std::max(1.0, brute));
        // The plan is a tree over all n primitives: children partition their parent, every group has >= 2.
        for (const OptimalGroup& g : plan.groups) {
            EXPECT_GE(g.children.size(), 2u);
            std::uint32_t u = 0;
            for (std::uint32_t c : g.children) {
                EXPECT_EQ(u & c, 0u);
                u |= c;
            }
            EXPECT_EQ(u, g.covered);
        }
        if (n > 1) {
            EXPECT_EQ(plan.groups.front().covered, (1u << n) - 1u);
        }
    }
}

/// Eq. 2 of a built hierarchy, the same as stats' cost().
double tree_cost(const Bvh& bvh, const VolumePolicy& policy) { return cost(bvh, policy); }

TEST(OptimalHierarchy, BuildEqualsEnumerationOnSmallScenes) {
    for (std::uint32_t n = 2; n <= 7; ++n) {
        for (std::uint64_t seed = 1; seed <= 3; ++seed) {
            const auto primitives = generate_scene({.count = n, .seed = seed * 31 + n});
            const VolumePolicy policy = seed == 2 ? VolumePolicy::only(BvType::aabb) : VolumePolicy::all();
            std::vector<double> volume(1u << n, 0.0);
            for (std::uint32_t s = 1; s < (1u << n); ++s) {
                FitInput input;
                for (std::uint32_t i = 0; i < n; ++i)
                    if (s >> i & 1u) input.add(primitives[i].volume);
                volume[s] = policy.weighted_volume(fit_best(input.spheres, policy, input.hint_axes));
            }
            std::map<std::uint32_t, std::vector<double>> memo;
            const auto& costs = all_tree_costs((1u << n) - 1u, volume, memo);
            const double brute = *std::min_element(costs.begin(), costs.end());

            BuildReport report;
            const Result<Bvh> bvh = build_optimal(primitives, test_support::context_for(policy, &report), {});
            ASSERT_TRUE(bvh.has_value());
            EXPECT_TRUE(validate(*bvh).has_value());
            EXPECT_NEAR(tree_cost(*bvh, policy), brute, 1e-9 * brute) << "n=" << n << " seed=" << seed;
            EXPECT_NEAR(report.lower_bound, brute, 1e-9 * brute);
        }
    }
}

TEST(OptimalHierarchy, NoWorseThanAnyRegisteredBuilder) {
    for (std::uint64_t seed : {5u, 6u, 7u}) {
        const auto primitives = generate_scene({.count = 9, .seed = seed});
        BuildContext options;
        const Result<Bvh> optimal = build(primitives, Algorithm::optimal, options);
        ASSERT_TRUE(optimal.has_value());
        const double optimal_cost = tree_cost(*optimal, options.policy);
        for (const AlgorithmInfo& info : algorithms()) {
            const Result<Bvh> other = build(primitives, info.algorithm(), options);
            if (!other.has_value()) continue;
            EXPECT_LE(optimal_cost, tree_cost(*other, options.policy) * (1.0 + 1e-9)) << info.name << " seed " << seed;
        }
    }
}

TEST(OptimalHierarchy, RefusesOrFallsBackAboveTheLimitAndHandlesOnePrimitive) {
    const auto many = generate_scene({.count = 19, .seed = 1});
    const Result<Bvh> refused = build_optimal(many, test_support::context_for(VolumePolicy::all()), {.max_primitives = 18, .fall_back = false});
    ASSERT_FALSE(refused.has_value());
    EXPECT_NE(refused.error().message.find("at most 18"), std::string::npos);
    const auto few = generate_scene({.count = 6, .seed = 1});
    BuildReport report;
    const Result<Bvh> fallback = build_optimal(few, test_support::context_for(VolumePolicy::all(), &report), {.max_primitives = 4});
    ASSERT_TRUE(fallback.has_value());  // fall_back: bnb-exact's tree, noted in the report
    EXPECT_TRUE(validate(*fallback).has_value());
    EXPECT_EQ(report.lower_bound, 0.0);
    EXPECT_FALSE(report.notes.empty());
    EXPECT_EQ(report.built_by, "bnb-exact");
    BuildReport within;
    ASSERT_TRUE(build_optimal(few, test_support::context_for(VolumePolicy::all(), &within)).has_value());
    EXPECT_EQ(within.built_by, "");  // the DP's own tree
    EXPECT_FALSE(build_optimal(std::span<const Primitive>{}, test_support::context_for(VolumePolicy::all())).has_value());
    const auto one = generate_scene({.count = 1, .seed = 1});
    const Result<Bvh> leaf = build_optimal(one, test_support::context_for(VolumePolicy::all()));
    ASSERT_TRUE(leaf.has_value());
    EXPECT_EQ(leaf->nodes.size(), 1u);
}

TEST(OptimalHierarchy, DeterministicTree) {
    const auto primitives = generate_scene({.count = 7, .seed = 12});
    const Result<Bvh> a = build_optimal(primitives, test_support::context_for(VolumePolicy::all()));
    const Result<Bvh> b = build_optimal(primitives, test_support::context_for(VolumePolicy::all()));
    ASSERT_TRUE(a && b);
    ASSERT_EQ(a->nodes.size(), b->nodes.size());
    for (std::size_t i = 0; i < a->nodes.size(); ++i) {
        EXPECT_EQ(a->nodes[i].child_count, b->nodes[i].child_count);
        EXPECT_EQ(a->nodes[i].primitive, b->nodes[i].primitive);
    }
}

}  // namespace
}  // namespace hbvh
