// SPDX-License-Identifier: MIT
// solve_exact against exhaustive enumeration on thousands of random small set-partition instances.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "builders/set_partition.hpp"
#include "hbvh/scene/generate.hpp"

namespace hbvh {
namespace {

constexpr double infinity = std::numeric_limits<double>::infinity();

/// Optimum by trying every subset of candidates (independent of any search order); infinity if none.
double optimum_by_subsets(std::uint32_t node_count, const std::vector<Candidate>& candidates) {
    const std::uint32_t n = static_cast<std::uint32_t>(candidates.size());
    std::vector<std::uint32_t> mask(n, 0);
    for (std::uint32_t i = 0; i < n; ++i)
        for (std::uint32_t j : candidates[i].members) mask[i] |= 1u << j;
    const std::uint32_t full = (1u << node_count) - 1u;
    double best = infinity;
    for (std::uint32_t pick = 0; pick < (1u << n); ++pick) {
        std::uint32_t covered = 0;
        double cost = 0.0;
        bool ok = true;
        for (std::uint32_t i = 0; i < n && ok; ++i) {
            if (!(pick >> i & 1u)) continue;
            if (covered & mask[i]) ok = false;
            covered |= mask[i];
            cost += candidates[i].cost;
        }
        if (ok && covered == full) best = std::min(best, cost);
    }
    return best;
}

/// Optimum by plain recursion on the lowest uncovered node, no bounds (for larger candidate lists).
double optimum_by_recursion(std::uint32_t full, std::uint32_t covered, const std::vector<std::uint32_t>& mask,
                            const std::vector<Candidate>& candidates) {
    if (covered == full) return 0.0;
    std::uint32_t lowest = 0;
    while (covered >> lowest & 1u) ++lowest;
    double best = infinity;
    for (std::size_t i = 0; i < mask.size(); ++i)
        if ((mask[i] >> lowest & 1u) && !(mask[i] & covered))
            best = std::min(best, candidates[i].cost + optimum_by_recursion(full, covered | mask[i], mask, candidates));
    return best;
}

double exhaustive_optimum(std::uint32_t node_count, const std::vector<Candidate>& candidates) {
    if (candidates.size() <= 12) return optimum_by_subsets(node_count, candidates);
    std::vector<std::uint32_t> mask;
    for (const Candidate& c : candidates) {
        std::uint32_t m = 0;
        for (std::uint32_t j : c.members) m |= 1u << j;
        mask.push_back(m);
    }
    return optimum_by_recursion((1u << node_count) - 1u, 0, mask, candidates);
}

/// A random instance: n <= 10 nodes, random candidates of size 1..4 (or any size), sometimes all singletons.
std::vector<Candidate> random_instance(SplitMix64& rng, std::uint32_t& node_count) {
    node_count = 1 + static_cast<std::uint32_t>(rng.below(10));
    const std::uint32_t count = static_cast<std::uint32_t>(rng.below(node_count <= 6 ? 12 : 30));
    const bool any_size = rng.below(3) == 0;
    const bool integer_costs = rng.below(4) == 0;  // many ties
    std::vector<Candidate> candidates;
    auto make_cost = [&](std::size_t size) {
        if (integer_costs) return static_cast<double>(1 + rng.below(5));
        return static_cast<double>(size) * rng.uniform(0.1, 3.0);
    };
    for (std::uint32_t i = 0; i < count; ++i) {
        const std::uint32_t size = 1 + static_cast<std::uint32_t>(rng.below(any_size ? node_count : std::min(node_count, 4u)));
        std::vector<std::uint32_t> members;
        while (members.size() < size) {
            const auto j = static_cast<std::uint32_t>(rng.below(node_count));
            if (std::find(members.begin(), members.end(), j) == members.end()) members.push_back(j);
        }
        std::sort(members.begin(), members.end());
        candidates.push_back({members, make_cost(size)});
    }
    if (rng.below(3) == 0) {
        for (std::uint32_t j = 0; j < node_count; ++j) candidates.push_back({{j}, make_cost(1) * 2.0});
    }
    return candidates;
}

void expect_valid_partition(std::uint32_t node_count, const std::vector<Candidate>& candidates, const Partition& p) {
    std::vector<int> times(node_count, 0);
    double cost = 0.0;
    for (std::size_t i = 0; i < p.chosen.size(); ++i) {
        ASSERT_LT(p.chosen[i], candidates.size());
        if (i > 0) {
            EXPECT_LT(p.chosen[i - 1], p.chosen[i]);
        }
        for (std::uint32_t j : candidates[p.chosen[i]].members) ++times[j];
        cost += candidates[p.chosen[i]].cost;
    }
    for (std::uint32_t j = 0; j < node_count; ++j) EXPECT_EQ(times[j], 1) << "node " << j;
    EXPECT_NEAR(cost, p.cost, 1e-12);
}

TEST(ExactSetPartition, MatchesExhaustiveEnumerationOnRandomInstances) {
    SplitMix64 rng(20260601);
    int infeasible = 0;
    int feasible = 0;
    for (int trial = 0; trial < 4000; ++trial) {
        std::uint32_t node_count = 0;
        const std::vector<Candidate> candidates = random_instance(rng, node_count);
        const double expected = exhaustive_optimum(node_count, candidates);
        const std::optional<Partition> p = solve_exact(node_count, candidates);
        if (expected == infinity) {
            EXPECT_FALSE(p.has_value()) << "trial " << trial;
            ++infeasible;
            continue;
        }
        ++feasible;
        ASSERT_TRUE(p.has_value()) << "trial " << trial;
        EXPECT_NEAR(p->cost, expected, 1e-9) << "trial " << trial;
        EXPECT_FALSE(p->budget_hit);
        EXPECT_EQ(p->lower_bound, p->cost);
        expect_valid_partition(node_count, candidates, *p);
    }
    // The generator must exercise both outcomes.
    EXPECT_GT(infeasible, 200);
    EXPECT_GT(feasible, 1000);
}

TEST(ExactSetPartition, TableOneOfTheSurvey) {
    // Survey Table 1 with c_i = min(OBB, sphere): the optimum picks candidates 2 and 3, cost 4 + 13 = 17.
    const std::vector<Candidate> candidates{{{2}, 9.0}, {{1}, 4.0}, {{0, 2}, 13.0}, {{0, 1}, 16.0}};
    const auto p = solve_exact(3, candidates);
    ASSERT_TRUE(p.has_value());
    EXPECT_EQ(p->chosen, (std::vector<std::uint32_t>{1, 2}));
    EXPECT_DOUBLE_EQ(p->cost, 17.0);
}

TEST(ExactSetPartition, EdgeCases) {
    EXPECT_TRUE(solve_exact(0, {}).has_value());
    EXPECT_FALSE(solve_exact(2, {}).has_value());
    const std::vector<Candidate> gap{{{0}, 1.0}, {{2}, 1.0}};
    EXPECT_FALSE(solve_exact(3, gap).has_value());
    const std::vector<Candidate> overlap_only{{{0, 1}, 1.0}, {{1, 2}, 1.0}};
    EXPECT_FALSE(solve_exact(3, overlap_only).has_value());
    // An empty candidate covers nothing and is never chosen.
    const std::vector<Candidate> with_empty{{{}, -5.0}, {{0, 1}, 2.0}};
    const auto p = solve_exact(2, with_empty);
    ASSERT_TRUE(p.has_value());
    EXPECT_EQ(p->chosen, (std::vector<std::uint32_t>{1}));
}

/// A larger instance: 60 nodes on a line, candidates = windows of 2..5 consecutive nodes with noisy costs.
std::vector<Candidate> window_instance(std::uint32_t node_count, std::uint64_t seed) {
    SplitMix64 rng(seed);
    std::vector<Candidate> candidates;
    for (std::uint32_t first = 0; first < node_count; ++first)
        for (std::uint32_t size = 2; size <= 5 && first + size <= node_count; ++size) {
            Candidate c;
            for (std::uint32_t j = first; j < first + size; ++j) c.members.push_back(j);
            c.cost = static_cast<double>(size) * rng.uniform(1.0, 2.0);
            candidates.push_back(std::move(c));
        }
    return candidates;
}

/// Optimum of a window instance by dynamic programming over prefixes.
double window_optimum(std::uint32_t node_count, const std::vector<Candidate>& candidates) {
    std::vector<double> best(node_count + 1, infinity);
    best[0] = 0.0;
    for (std::uint32_t end = 1; end <= node_count; ++end)
        for (const Candidate& c : candidates)
            if (c.members.back() + 1 == end) best[end] = std::min(best[end], best[c.members.front()] + c.cost);
    return best[node_count];
}

TEST(ExactSetPartition, HundredsOfNodes) {
    const std::uint32_t n = 300;
    const auto candidates = window_instance(n, 7);
    const auto p = solve_exact(n, candidates);
    ASSERT_TRUE(p.has_value());
    EXPECT_FALSE(p->budget_hit);
    EXPECT_NEAR(p->cost, window_optimum(n, candidates), 1e-9);
    EXPECT_GT(p->nodes_explored, 0u);
    expect_valid_partition(n, candidates, *p);
}

TEST(ExactSetPartition, BudgetStopsWithBestFoundAndValidLowerBound) {
    // Hard for a per-node bound: random candidates of sizes 2-3 over 40 nodes with many alternatives.
    SplitMix64 rng(99);
    const std::uint32_t n = 40;
    std::vector<Candidate> candidates;
    for (std::uint32_t j = 0; j < n; ++j) candidates.push_back({{j}, 10.0});  // greedy always completes
    for (std::uint32_t j = 0; j + 1 < n; ++j) candidates.push_back({{j, j + 1}, rng.uniform(1.0, 2.0)});
    for (int i = 0; i < 600; ++i) {
        std::vector<std::uint32_t> m;
        const std::uint32_t size = 2 + static_cast<std::uint32_t>(rng.below(2));
        while (m.size() < size) {
            const auto j = static_cast<std::uint32_t>(rng.below(n));
            if (std::find(m.begin(), m.end(), j) == m.end()) m.push_back(j);
        }
        std::sort(m.begin(), m.end());
        candidates.push_back({m, static_cast<double>(size) * rng.uniform(0.5, 1.5)});
    }
    const auto full = solve_exact(n, candidates);
    ASSERT_TRUE(full.has_value());
    ASSERT_FALSE(full->budget_hit);
    ASSERT_GT(full->nodes_explored, 20u);

    const auto limited = solve_exact(n, candidates, SolverBudget{10, 0.0});
    ASSERT_TRUE(limited.has_value());  // the greedy + local-search start is always available
    EXPECT_TRUE(limited->budget_hit);
    EXPECT_LE(limited->nodes_explored, 10u);
    EXPECT_GE(limited->cost, full->cost - 1e-9);
    EXPECT_LE(limited->lower_bound, full->cost + 1e-9);
    EXPECT_LE(limited->lower_bound, limited->cost);
    expect_valid_partition(n, candidates, *limited);

    const auto timed = solve_exact(n, candidates, SolverBudget{0, 1e-9});
    ASSERT_TRUE(timed.has_value());
    EXPECT_LE(timed->lower_bound, full->cost + 1e-9);
}

TEST(ExactSetPartition, EqualsReferenceSolverWhereEq7Holds) {
    // Instances shaped like real levels: node volumes v_j, candidate cost = |c| x (a volume at least the
    // members' total), so every cost is >= 2 x its members' volume and the survey's Eq. 7 bound is valid.
    SplitMix64 rng(777);
    for (int trial = 0; trial < 500; ++trial) {
        const std::uint32_t n = 2 + static_cast<std::uint32_t>(rng.below(11));
        std::vector<double> volumes(n);
        for (double& v : volumes) v = rng.uniform(0.5, 2.0);
        std::vector<Candidate> candidates;
        const std::uint32_t count = 1 + static_cast<std::uint32_t>(rng.below(3 * n));
        for (std::uint32_t i = 0; i < count; ++i) {
            const std::uint32_t size = 2 + static_cast<std::uint32_t>(rng.below(std::min(n - 1, 4u)));
            std::vector<std::uint32_t> m;
            while (m.size() < size) {
                const auto j = static_cast<std::uint32_t>(rng.below(n));
                if (std::find(m.begin(), m.end(), j) == m.end()) m.push_back(j);
            }
            std::sort(m.begin(), m.end());
            double total = 0.0;
            for (std::uint32_t j : m) total += volumes[j];
            candidates.push_back({m, static_cast<double>(size) * total * rng.uniform(1.0, 1.6)});
        }
        const auto exact = solve_exact(n, candidates);
        const auto reference = solve_reference_branch_and_bound(n, candidates, volumes);
        ASSERT_EQ(exact.has_value(), reference.has_value()) << "trial " << trial;
        if (!exact) continue;
        EXPECT_FALSE(reference->budget_hit);
        EXPECT_NEAR(exact->cost, reference->cost, 1e-9) << "trial " << trial;
    }
}

TEST(ExactSetPartition, Deterministic) {
    const auto candidates = window_instance(80, 3);
    const auto a = solve_exact(80, candidates);
    const auto b = solve_exact(80, candidates);
    ASSERT_TRUE(a && b);
    EXPECT_EQ(a->chosen, b->chosen);
    EXPECT_EQ(a->nodes_explored, b->nodes_explored);
}

}  // namespace
}  // namespace hbvh
