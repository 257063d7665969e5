// SPDX-License-Identifier: MIT
// build_optimal / solve_optimal_hierarchy against explicit enumeration of every hierarchy.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <limits>
#include <filesystem>
#include <functional>
#include <map>

#include "support/test_helpers.hpp"
#include "hbvh/io/xml.hpp"
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

/// The optimum by a second, slower recursion, for sizes enumeration cannot reach: for a parent of volume w,
/// cover(T) = min over blocks B holding T's lowest member of (w + best(B)) + cover(T \ B), each block paying
/// w for its place among the children; best(S) takes the block of S's lowest member as a proper subset, so a
/// node has two children or more. 4^n work.
double optimum_by_covers(std::uint32_t n, const std::vector<double>& volume) {
    std::vector<double> best(1u << n, 0.0);
    for (std::uint32_t s = 1; s < (1u << n); ++s) {
        if (std::popcount(s) == 1) continue;
        const double w = volume[s];
        std::map<std::uint32_t, double> cover{{0u, 0.0}};
        const std::function<double(std::uint32_t)> cover_of = [&](std::uint32_t t) {
            if (auto it = cover.find(t); it != cover.end()) return it->second;
            const std::uint32_t low = t & (~t + 1u);
            double least = std::numeric_limits<double>::infinity();
            for (std::uint32_t sub = t ^ low;; sub = (sub - 1u) & (t ^ low)) {
                least = std::min(least, w + best[low | sub] + cover_of(t ^ (low | sub)));
                if (sub == 0) break;
            }
            return cover[t] = least;
        };
        const std::uint32_t low = s & (~s + 1u);
        const std::uint32_t rest = s ^ low;
        double least = std::numeric_limits<double>::infinity();
        for (std::uint32_t sub = (rest - 1u) & rest;; sub = (sub - 1u) & rest) {
            least = std::min(least, w + best[low | sub] + cover_of(s ^ (low | sub)));
            if (sub == 0) break;
        }
        best[s] = least;
    }
    return best.back();
}

/// A random volume function with ties, over n members.
std::vector<double> random_volumes(SplitMix64& rng, std::uint32_t n) {
    std::vector<double> volume(1u << n, 0.0);
    for (std::uint32_t s = 1; s < (1u << n); ++s)
        volume[s] = rng.below(4) == 0 ? static_cast<double>(rng.below(3) + 1)
                                      : static_cast<double>(std::popcount(s)) * rng.uniform(0.2, 2.0);
    return volume;
}

/// fit_best's weighted volume over every subset, as build_optimal fits them (FitInput in input order).
std::vector<double> every_fit(std::span<const Primitive> primitives, const VolumePolicy& policy) {
    const auto n = static_cast<std::uint32_t>(primitives.size());
    std::vector<double> volume(1u << n, 0.0);
    for (std::uint32_t s = 1; s < (1u << n); ++s) {
        if (std::popcount(s) < 2) continue;
        FitInput input;
        for (std::uint32_t i = 0; i < n; ++i)
            if (s >> i & 1u) input.add(primitives[i].volume);
        volume[s] = policy.weighted_volume(fit_best(input.spheres, policy, input.hint_axes));
    }
    return volume;
}

/// How many subsets build_optimal fitted, from its report's note.
std::uint64_t fitted_subsets(const BuildReport& report) {
    for (const std::string& note : report.notes)
        if (const auto at = note.find(" subsets, "); at != std::string::npos)
            return std::stoull(note.substr(at + 10));
    ADD_FAILURE() << "no fit count in the report";
    return 0;
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
            const std::vector<double> volume = every_fit(primitives, policy);
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

TEST(OptimalHierarchy, ParallelSizesEqualASecondRecursion) {
    // From 12 members the DP solves the subsets of one size in parallel: the same optimum as a recursion
    // written another way, on volume functions with ties.
    SplitMix64 rng(77);
    for (std::uint32_t n : {8u, 12u, 13u}) {
        const std::vector<double> volume = random_volumes(rng, n);
        const OptimalPlan plan = solve_optimal_hierarchy(n, volume);
        const double expected = optimum_by_covers(n, volume);
        EXPECT_NEAR(plan.cost, expected, 1e-9 * expected) << "n=" << n;
        EXPECT_NEAR(plan_cost(plan, volume), plan.cost, 1e-9 * expected);
    }
}

TEST(OptimalHierarchy, OutsideCostIsTheCheapestTreeThroughEachSet) {
    // best(S) + outside(S) against the optimum of the problem with S contracted into one leaf that costs
    // best(S) (every tree with S as a node is such a tree with S's subtree hung at that leaf).
    SplitMix64 rng(91);
    for (std::uint32_t n : {6u, 12u}) {
        const std::vector<double> volume = random_volumes(rng, n);
        const detail::SubsetTables tables = detail::solve_subsets(n, volume);
        const std::vector<double> outside = detail::cost_outside(tables, volume);
        const std::uint32_t full = (1u << n) - 1u;
        int checked = 0;
        for (std::uint32_t s = 3; s < full; s += n < 10 ? 1 : 37) {
            if (std::popcount(s) < 2) continue;
            // The contracted items: S's members as item 0, every other member as one item each.
            std::vector<std::uint32_t> item_bits{s};
            for (std::uint32_t i = 0; i < n; ++i)
                if (!(s >> i & 1u)) item_bits.push_back(1u << i);
            const auto m = static_cast<std::uint32_t>(item_bits.size());
            std::vector<double> contracted(1u << m, 0.0);
            for (std::uint32_t c = 1; c < (1u << m); ++c) {
                std::uint32_t bits = 0;
                for (std::uint32_t j = 0; j < m; ++j)
                    if (c >> j & 1u) bits |= item_bits[j];
                contracted[c] = volume[bits];
            }
            const double expected = tables.best[s] + solve_optimal_hierarchy(m, contracted).cost;
            EXPECT_NEAR(tables.best[s] + outside[s], expected, 1e-9 * expected) << "n=" << n << " S=" << s;
            ++checked;
        }
        EXPECT_GT(checked, 50);
        EXPECT_EQ(outside[full], 0.0);
    }
}

TEST(OptimalHierarchy, FitsOnDemandGiveTheOptimumOverEveryFit) {
    // The builder fits only the subsets its rounds ask for; its tree must cost what the DP over every subset's
    // fit gives, under weights and the Minkowski measure too (the bounds scale with both).
    VolumePolicy weighted = VolumePolicy::all();
    weighted.weight = {1.0, 1.3, 0.45, 1.8};
    VolumePolicy minkowski = VolumePolicy::all();
    minkowski.measure = NodeMeasure::minkowski;
    const std::vector<VolumePolicy> policies{VolumePolicy::all(), weighted, minkowski,
                                             VolumePolicy::only(BvType::capsule), VolumePolicy::only(BvType::obb)};
    std::uint64_t fitted = 0, subsets = 0;
    for (std::uint32_t n : {9u, 11u}) {
        const auto primitives = generate_scene({.count = n, .seed = 40u + n});
        for (const VolumePolicy& policy : policies) {
            const double expected = solve_optimal_hierarchy(n, every_fit(primitives, policy)).cost;
            BuildReport report;
            const Result<Bvh> bvh = build_optimal(primitives, test_support::context_for(policy, &report));
            ASSERT_TRUE(bvh.has_value());
            EXPECT_NEAR(tree_cost(*bvh, policy), expected, 1e-12 * expected) << "n=" << n;
            EXPECT_NEAR(report.lower_bound, expected, 1e-12 * expected);
            fitted += fitted_subsets(report);
            subsets += (1u << n) - n - 1;
        }
    }
    // The chair, where the bounds are tight: most subsets are never fitted.
    const Result<XmlModel> chair =
        read_xml_file(std::filesystem::path(HBVH_SOURCE_DIR) / "data" / "models" / "chair.xml");
    ASSERT_TRUE(chair.has_value());
    BuildReport report;
    const Result<Bvh> bvh = build_optimal(chair->primitives, test_support::context_for(VolumePolicy::all(), &report));
    ASSERT_TRUE(bvh.has_value());
    const double expected = solve_optimal_hierarchy(13, every_fit(chair->primitives, VolumePolicy::all())).cost;
    EXPECT_NEAR(tree_cost(*bvh, VolumePolicy::all()), expected, 1e-12 * expected);
    EXPECT_LT(fitted_subsets(report), 8178u / 4);
    EXPECT_LE(fitted, subsets);
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
