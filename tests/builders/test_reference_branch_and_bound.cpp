// SPDX-License-Identifier: MIT
// The survey's branch and bound (Appendix A) against exhaustive enumeration, its Table 1 example, the
// instance where Eq. 7 prunes the optimum, budgets and instances without an exact cover.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "builders/set_partition.hpp"
#include "hbvh/geometry/aabb.hpp"
#include "hbvh/scene/generate.hpp"

namespace hbvh {
namespace {

/// Cheapest exact cover by trying every subset of candidates (only for a handful of candidates).
std::optional<double> cheapest_cover_by_enumeration(std::uint32_t node_count, const std::vector<Candidate>& candidates) {
    std::optional<double> best;
    const std::uint32_t subsets = 1u << candidates.size();
    std::vector<int> hits(node_count);
    for (std::uint32_t subset = 0; subset < subsets; ++subset) {
        std::fill(hits.begin(), hits.end(), 0);
        double cost = 0.0;
        for (std::uint32_t i = 0; i < candidates.size(); ++i) {
            if (!(subset >> i & 1u)) continue;
            cost += candidates[i].cost;
            for (std::uint32_t member : candidates[i].members) ++hits[member];
        }
        if (std::all_of(hits.begin(), hits.end(), [](int h) { return h == 1; }) && (!best || cost < *best)) best = cost;
    }
    return best;
}

/// True when `chosen` covers every node exactly once and its costs add up to `cost`.
bool is_exact_cover(std::uint32_t node_count, const std::vector<Candidate>& candidates, const Partition& partition) {
    std::vector<int> hits(node_count, 0);
    double cost = 0.0;
    for (std::uint32_t index : partition.chosen) {
        if (index >= candidates.size()) return false;
        cost += candidates[index].cost;
        for (std::uint32_t member : candidates[index].members) ++hits[member];
    }
    return std::all_of(hits.begin(), hits.end(), [](int h) { return h == 1; }) &&
           std::abs(cost - partition.cost) <= 1e-9 * std::max(1.0, cost);
}

/// A random instance. With `admissible`, every cost is at least 2 x its members' volume, so Eq. 7 holds.
/// Half the instances get a hidden random partition among the candidates so that a cover exists.
struct Instance {
    std::uint32_t node_count = 0;
    std::vector<Candidate> candidates;
    std::vector<double> volumes;
};
Instance random_reference_instance(SplitMix64& rng, bool admissible) {
    Instance instance;
    instance.node_count = 1 + static_cast<std::uint32_t>(rng.below(8));
    for (std::uint32_t j = 0; j < instance.node_count; ++j) instance.volumes.push_back(rng.uniform(0.1, 3.0));
    auto add = [&](std::vector<std::uint32_t> members) {
        std::sort(members.begin(), members.end());
        members.erase(std::unique(members.begin(), members.end()), members.end());
        double volume = 0.0;
        for (std::uint32_t m : members) volume += instance.volumes[m];
        const double cost = admissible ? 2.0 * volume * rng.uniform(1.0, 2.0) : volume * rng.uniform(0.2, 3.0);
        instance.candidates.push_back({std::move(members), cost});
    };
    const auto random_count = static_cast<std::uint32_t>(rng.below(11));
    for (std::uint32_t c = 0; c < random_count; ++c) {
        std::vector<std::uint32_t> members;
        for (std::uint32_t j = 0; j < instance.node_count; ++j)
            if (rng.below(3) == 0) members.push_back(j);
        if (members.empty()) members.push_back(static_cast<std::uint32_t>(rng.below(instance.node_count)));
        add(std::move(members));
    }
    if (rng.below(2) == 0) {
        std::vector<std::uint32_t> group_of(instance.node_count);
        const std::uint32_t groups = 1 + static_cast<std::uint32_t>(rng.below(instance.node_count));
        for (std::uint32_t j = 0; j < instance.node_count; ++j) group_of[j] = static_cast<std::uint32_t>(rng.below(groups));
        for (std::uint32_t g = 0; g < groups; ++g) {
            std::vector<std::uint32_t> members;
            for (std::uint32_t j = 0; j < instance.node_count; ++j)
                if (group_of[j] == g) members.push_back(j);
            if (!members.empty()) add(std::move(members));
        }
    }
    // Shuffle the list: the survey's search order depends on it.
    for (std::size_t i = instance.candidates.size(); i > 1; --i) std::swap(instance.candidates[i - 1], instance.candidates[rng.below(i)]);
    return instance;
}

TEST(ReferenceBranchAndBound, MatchesExhaustiveSearchWhenEq7Holds) {
    SplitMix64 rng(2024);
    int with_cover = 0;
    for (int trial = 0; trial < 4000; ++trial) {
        const Instance instance = random_reference_instance(rng, true);
        const std::optional<double> expected = cheapest_cover_by_enumeration(instance.node_count, instance.candidates);
        const std::optional<Partition> found =
            solve_reference_branch_and_bound(instance.node_count, instance.candidates, instance.volumes);
        ASSERT_EQ(expected.has_value(), found.has_value()) << "trial " << trial;
        if (!expected) continue;
        ++with_cover;
        ASSERT_TRUE(is_exact_cover(instance.node_count, instance.candidates, *found)) << "trial " << trial;
        EXPECT_NEAR(found->cost, *expected, 1e-9 * std::max(1.0, *expected)) << "trial " << trial;
        EXPECT_FALSE(found->budget_hit);
        EXPECT_EQ(found->lower_bound, found->cost);  // admissible bound + complete search = proven optimum
        EXPECT_TRUE(std::is_sorted(found->chosen.begin(), found->chosen.end()));
    }
    EXPECT_GT(with_cover, 1500);
}

TEST(ReferenceBranchAndBound, NeverBetterThanExhaustiveAndFindsACoverWheneverOneExists) {
    // Without the Eq. 7 guarantee the survey's search may prune the optimum, but pruning needs a registered
    // solution first, so it still finds some cover exactly when one exists.
    SplitMix64 rng(77);
    for (int trial = 0; trial < 3000; ++trial) {
        const Instance instance = random_reference_instance(rng, false);
        const std::optional<double> expected = cheapest_cover_by_enumeration(instance.node_count, instance.candidates);
        const std::optional<Partition> found =
            solve_reference_branch_and_bound(instance.node_count, instance.candidates, instance.volumes);
        ASSERT_EQ(expected.has_value(), found.has_value()) << "trial " << trial;
        if (!expected) continue;
        ASSERT_TRUE(is_exact_cover(instance.node_count, instance.candidates, *found));
        EXPECT_GE(found->cost, *expected - 1e-9 * std::max(1.0, *expected));
        EXPECT_LE(found->lower_bound, *expected + 1e-9 * std::max(1.0, *expected));  // always a true bound
    }
}

TEST(ReferenceBranchAndBound, SurveyTable1) {
    // Table 1 (bits read right to left: "110" merges the second and third nodes), c_i = min(OBB, sphere).
    const std::vector<Candidate> candidates{
        {{0}, std::min(9.0, 10.0)},
        {{1}, std::min(4.0, 6.0)},
        {{0, 2}, std::min(15.0, 13.0)},
        {{1, 2}, std::min(16.0, 21.0)},
    };
    const std::vector<double> volumes{1.0, 1.0, 1.0};
    const std::optional<Partition> found = solve_reference_branch_and_bound(3, candidates, volumes);
    ASSERT_TRUE(found.has_value());
    EXPECT_DOUBLE_EQ(found->cost, 17.0);
    EXPECT_EQ(found->chosen, (std::vector<std::uint32_t>{1, 2}));  // the survey's candidates 2 and 3
    EXPECT_GT(found->nodes_explored, 0u);
}

TEST(ReferenceBranchAndBound, Eq7PrunesTheOptimumWhenChildrenOverlap) {
    // docs/algorithms.md: two pairs of coincident unit cubes, the pairs half overlapping. Costs are
    // 2 x the fitted AABB volume for a pair and 4 x for the whole level.
    const Aabb left{Vec3(0, 0, 0), Vec3(1, 1, 1)};
    const Aabb right{Vec3(0.5, 0, 0), Vec3(1.5, 1, 1)};
    const std::vector<Aabb> nodes{left, left, right, right};
    auto cost_of = [&](const std::vector<std::uint32_t>& members) {
        Aabb box = Aabb::empty();
        for (std::uint32_t m : members) box = box.merged(nodes[m]);  // the exact AABB fit of boxes
        return static_cast<double>(members.size()) * box.volume();
    };
    std::vector<Candidate> candidates;
    for (std::vector<std::uint32_t> members : {std::vector<std::uint32_t>{0, 1}, {2, 3}, {0, 1, 2, 3}})
        candidates.push_back({members, cost_of(members)});
    EXPECT_DOUBLE_EQ(candidates[0].cost, 2.0);
    EXPECT_DOUBLE_EQ(candidates[1].cost, 2.0);
    EXPECT_DOUBLE_EQ(candidates[2].cost, 6.0);
    const std::vector<double> volumes{1.0, 1.0, 1.0, 1.0};

    const std::optional<Partition> found = solve_reference_branch_and_bound(4, candidates, volumes);
    ASSERT_TRUE(found.has_value());
    EXPECT_DOUBLE_EQ(found->cost, 6.0);  // the whole level, found first; the root bound 2 x 4 = 8 > 6 prunes the rest
    EXPECT_EQ(found->chosen, (std::vector<std::uint32_t>{2}));
    EXPECT_DOUBLE_EQ(*cheapest_cover_by_enumeration(4, candidates), 4.0);  // the two pairs
    EXPECT_LT(found->lower_bound, found->cost);                  // not claimed optimal
    EXPECT_LE(found->lower_bound, 4.0);
}

TEST(ReferenceBranchAndBound, NoExactCoverGivesNullopt) {
    const std::vector<double> volumes{1.0, 1.0, 1.0};
    // Three pairs over three nodes: every two overlap, none covers node set alone.
    const std::vector<Candidate> pairs{{{0, 1}, 4.0}, {{1, 2}, 4.0}, {{0, 2}, 4.0}};
    EXPECT_FALSE(solve_reference_branch_and_bound(3, pairs, volumes).has_value());
    // A node no candidate contains.
    const std::vector<Candidate> missing{{{0, 1}, 4.0}};
    EXPECT_FALSE(solve_reference_branch_and_bound(3, missing, volumes).has_value());
    EXPECT_FALSE(solve_reference_branch_and_bound(3, {}, volumes).has_value());
    // Zero nodes: the empty partition.
    const std::optional<Partition> empty = solve_reference_branch_and_bound(0, {}, {});
    ASSERT_TRUE(empty.has_value());
    EXPECT_TRUE(empty->chosen.empty());
}

TEST(ReferenceBranchAndBound, ManyNodesUseSeveralBitsetWords) {
    // 130 nodes, beyond the survey's 32-bit selector; candidates straddle the word boundaries at 64 and 128.
    const std::uint32_t n = 130;
    std::vector<double> volumes(n, 1.0);
    auto range = [](std::uint32_t first, std::uint32_t last) {
        std::vector<std::uint32_t> members;
        for (std::uint32_t i = first; i < last; ++i) members.push_back(i);
        return members;
    };
    const std::vector<Candidate> candidates{{range(0, n), 1000.0}, {range(0, 70), 300.0}, {range(60, 100), 10.0},
                                            {range(70, n), 300.0}};
    const std::optional<Partition> found = solve_reference_branch_and_bound(n, candidates, volumes);
    ASSERT_TRUE(found.has_value());
    EXPECT_DOUBLE_EQ(found->cost, 600.0);
    EXPECT_EQ(found->chosen, (std::vector<std::uint32_t>{1, 3}));
    EXPECT_TRUE(is_exact_cover(n, candidates, *found));
}

/// All pairs over n nodes with random costs, then (last in the list, as the survey's Tightest lists end)
/// the whole level, so that the skip-first search meets a cover at once.
std::vector<Candidate> pairs_then_whole_level(std::uint32_t n, std::uint64_t seed) {
    SplitMix64 rng(seed);
    std::vector<Candidate> candidates;
    for (std::uint32_t i = 0; i < n; ++i)
        for (std::uint32_t j = i + 1; j < n; ++j) candidates.push_back({{i, j}, 2.0 + rng.uniform()});
    Candidate whole;
    for (std::uint32_t i = 0; i < n; ++i) whole.members.push_back(i);
    whole.cost = 4.0 * n;
    candidates.push_back(whole);
    return candidates;
}

TEST(ReferenceBranchAndBound, NodeBudgetStopsWithBestFound) {
    const std::uint32_t n = 24;
    const std::vector<double> volumes(n, 1.0);
    const std::vector<Candidate> candidates = pairs_then_whole_level(n, 5);
    SolverBudget budget;
    budget.max_nodes = 5000;
    const std::optional<Partition> found = solve_reference_branch_and_bound(n, candidates, volumes, budget);
    ASSERT_TRUE(found.has_value());
    EXPECT_TRUE(found->budget_hit);
    EXPECT_EQ(found->nodes_explored, 5000u);
    EXPECT_TRUE(is_exact_cover(n, candidates, *found));
    EXPECT_LE(found->lower_bound, found->cost);

    // Stopped before any cover: nothing to return.
    const SolverBudget tiny{1, 0.0};
    EXPECT_FALSE(solve_reference_branch_and_bound(n, candidates, volumes, tiny).has_value());
}

TEST(ReferenceBranchAndBound, TimeBudgetStopsQuickly) {
    const std::uint32_t n = 40;
    const std::vector<double> volumes(n, 1.0);
    const std::vector<Candidate> candidates = pairs_then_whole_level(n, 9);
    SolverBudget budget;
    budget.max_seconds = 0.05;
    const auto start = std::chrono::steady_clock::now();
    const std::optional<Partition> found = solve_reference_branch_and_bound(n, candidates, volumes, budget);
    const std::chrono::duration<double> elapsed = std::chrono::steady_clock::now() - start;
    EXPECT_LT(elapsed.count(), 1.0);
    ASSERT_TRUE(found.has_value());
    EXPECT_TRUE(found->budget_hit);
    EXPECT_TRUE(is_exact_cover(n, candidates, *found));
}

}  // namespace
}  // namespace hbvh
