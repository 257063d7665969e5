// SPDX-License-Identifier: MIT
// B&B-Tightest and B&B-Enlarge end to end: validity, containment, no single-child groups, invariance
// under input permutations, filled reports; plus the bottom-up driver's fallbacks.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "hbvh/build/branch_and_bound.hpp"
#include "hbvh/build/build.hpp"
#include "hbvh/scene/generate.hpp"
#include "hbvh/tree/stats.hpp"
#include "hbvh/tree/validate.hpp"

namespace hbvh {
namespace {

constexpr Algorithm bnb_algorithms[] = {Algorithm::bnb_tightest, Algorithm::bnb_enlarge};

/// A small per-level budget keeps the exponential reference search inside the suite's time.
BuildOptions test_options(BuildReport* report) {
    BuildOptions options;
    options.report = report;
    options.branch_and_bound.budget.max_nodes = 200'000;
    return options;
}

std::vector<Primitive> shuffled(std::vector<Primitive> primitives, std::uint64_t seed) {
    SplitMix64 rng(seed);
    for (std::size_t i = primitives.size(); i > 1; --i) std::swap(primitives[i - 1], primitives[rng.below(i)]);
    return primitives;
}

/// The checks every hierarchy must pass, with messages naming the scene.
void expect_valid(const Bvh& bvh, std::size_t primitive_count, const std::string& what) {
    const Status status = validate(bvh, 1e-9);  // each primitive once, containment, >= 2 children
    EXPECT_TRUE(status.has_value()) << what << ": " << (status ? "" : status.error().to_string());
    std::uint32_t leaves = 0;
    for (const Node& node : bvh.nodes) {
        if (node.is_leaf()) {
            ++leaves;
        } else {
            EXPECT_GE(node.child_count, 2u) << what;
        }
    }
    EXPECT_EQ(leaves, primitive_count) << what;
}

void expect_report_filled(const BuildReport& report, std::size_t primitive_count, const std::string& what) {
    if (primitive_count < 2) {
        EXPECT_TRUE(report.levels.empty()) << what;
        return;
    }
    ASSERT_FALSE(report.levels.empty()) << what;
    EXPECT_EQ(report.levels.front().nodes, primitive_count) << what;
    EXPECT_EQ(report.levels.back().groups, 1u) << what;
    std::uint32_t total = 0;
    for (std::size_t i = 0; i < report.levels.size(); ++i) {
        const LevelReport& level = report.levels[i];
        EXPECT_LT(level.groups, level.nodes) << what;
        EXPECT_GE(level.seconds, 0.0) << what;
        if (i + 1 < report.levels.size()) {
            EXPECT_EQ(report.levels[i + 1].nodes, level.groups) << what;
        }
        if (!level.fallback_used) {
            EXPECT_GT(level.solver_nodes, 0u) << what;
        }
        total += level.candidates;
    }
    EXPECT_EQ(report.total_candidates, total) << what;
}

TEST(BranchAndBoundBuilders, AreRegistered) {
    EXPECT_EQ(parse_algorithm("bnb-tightest"), Algorithm::bnb_tightest);
    EXPECT_EQ(parse_algorithm("bnb-enlarge"), Algorithm::bnb_enlarge);
    EXPECT_EQ(to_string(Algorithm::bnb_enlarge), "bnb-enlarge");
}

TEST(BranchAndBoundBuilders, ValidOnGeneratedScenesAndInvariantUnderShuffles) {
    for (Algorithm algorithm : bnb_algorithms) {
        for (std::uint32_t count : {1u, 2u, 3u, 5u, 8u, 13u, 21u}) {
            for (bool clustered : {true, false}) {
                SceneOptions scene;
                scene.count = count;
                scene.seed = 100 + count;
                scene.clustered = clustered;
                const std::vector<Primitive> primitives = generate_scene(scene);
                const std::string what = std::string(to_string(algorithm)) + " n=" + std::to_string(count) +
                                         (clustered ? " clustered" : " uniform");
                BuildReport report;
                const Result<Bvh> bvh = build(primitives, algorithm, test_options(&report));
                ASSERT_TRUE(bvh.has_value()) << what;
                expect_valid(*bvh, count, what);
                expect_report_filled(report, count, what);
                const double reference_cost = cost(*bvh);
                for (std::uint64_t seed : {1u, 2u}) {
                    const Result<Bvh> other = build(shuffled(primitives, seed), algorithm, test_options(nullptr));
                    ASSERT_TRUE(other.has_value()) << what;
                    EXPECT_NEAR(cost(*other), reference_cost, 1e-9 * std::max(1.0, reference_cost))
                        << what << " shuffle " << seed;
                }
            }
        }
    }
}

TEST(BranchAndBoundBuilders, LargerSceneWithinBudget) {
    SceneOptions scene;
    scene.count = 30;
    scene.seed = 7;
    const std::vector<Primitive> primitives = generate_scene(scene);
    for (Algorithm algorithm : bnb_algorithms) {
        BuildReport report;
        const Result<Bvh> bvh = build(primitives, algorithm, test_options(&report));
        ASSERT_TRUE(bvh.has_value());
        expect_valid(*bvh, primitives.size(), std::string(to_string(algorithm)) + " n=30");
        expect_report_filled(report, primitives.size(), std::string(to_string(algorithm)) + " n=30");
        const Result<Bvh> other = build(shuffled(primitives, 3), algorithm, test_options(nullptr));
        ASSERT_TRUE(other.has_value());
        EXPECT_NEAR(cost(*other), cost(*bvh), 1e-9 * cost(*bvh));
    }
}

/// Opt-in survey of costs, times and candidate counts (run with --gtest_also_run_disabled_tests).
TEST(BranchAndBoundBuilders, DISABLED_PrintSurvey) {
    for (std::uint32_t count : {8u, 13u, 17u, 21u, 27u, 30u}) {
        SceneOptions scene;
        scene.count = count;
        scene.seed = 1000 + count;
        const std::vector<Primitive> primitives = generate_scene(scene);
        for (Algorithm algorithm : {Algorithm::two_level, Algorithm::bnb_tightest, Algorithm::bnb_enlarge}) {
            BuildReport report;
            BuildOptions options;
            options.report = &report;
            const auto start = std::chrono::steady_clock::now();
            const Result<Bvh> bvh = build(primitives, algorithm, options);
            const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            const Stats stats = compute_stats(*bvh);
            std::uint64_t solver_nodes = 0;
            int fallbacks = 0, budget_hits = 0;
            for (const LevelReport& level : report.levels) {
                solver_nodes += level.solver_nodes;
                fallbacks += level.fallback_used;
                budget_hits += level.budget_hit;
            }
            std::printf("n=%2u %-13s cost=%12.3f height=%u levels=%zu MC=%5u solver_nodes=%10llu fallbacks=%d "
                        "budget_hits=%d time=%.3fs\n",
                        count, std::string(to_string(algorithm)).c_str(), stats.cost, stats.height, report.levels.size(),
                        report.total_candidates, static_cast<unsigned long long>(solver_nodes), fallbacks, budget_hits,
                        seconds);
        }
    }
}

}  // namespace
}  // namespace hbvh
