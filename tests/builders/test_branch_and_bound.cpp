// SPDX-License-Identifier: MIT
// B&B-Tightest and B&B-Enlarge end to end: validity, containment, no single-child groups, invariance
// under input permutations, filled reports; plus the bottom-up driver's fallbacks.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "builders/survey_branch_and_bound.hpp"
#include "hbvh/builders/build.hpp"
#include "hbvh/fit/volume_policy.hpp"
#include "hbvh/io/xml.hpp"
#include "hbvh/scene/generate.hpp"
#include "hbvh/tree/stats.hpp"
#include "hbvh/tree/validate.hpp"
#include "support/bundled_models.hpp"
#include "support/test_helpers.hpp"

namespace hbvh {
namespace {

using test_support::shuffled;

constexpr Algorithm bnb_algorithms[] = {Algorithm::bnb_tightest, Algorithm::bnb_enlarge};

/// `algorithm` (bnb-tightest or bnb-enlarge) with a small per-level budget, which keeps the exponential
/// reference search inside the suite's time.
Result<Bvh> build_budgeted(std::span<const Primitive> primitives, Algorithm algorithm, const BuildContext& context) {
    constexpr std::uint64_t max_nodes = 200'000;
    if (algorithm == Algorithm::bnb_tightest) {
        BnbTightestOptions options;
        options.budget.max_nodes = max_nodes;
        return build_bnb_tightest(primitives, context, options);
    }
    BnbEnlargeOptions options;
    options.budget.max_nodes = max_nodes;
    return build_bnb_enlarge(primitives, context, options);
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
        for (std::uint32_t count : {1u, 2u, 3u, 5u, 8u, 13u, 21u, 30u}) {
            for (bool clustered : {true, false}) {
                if (count >= 21 && !clustered) continue;
                SceneOptions scene;
                scene.count = count;
                scene.seed = 100 + count;
                scene.clustered = clustered;
                const std::vector<Primitive> primitives = generate_scene(scene);
                const std::string what = std::string(to_string(algorithm)) + " n=" + std::to_string(count) +
                                         (clustered ? " clustered" : " uniform");
                BuildReport report;
                BuildContext options;
                options.report = &report;
                // Tightest's O(n^3) fits dominate the suite's time: the larger scenes use the two cheap kinds.
                if (count >= 21) options.policy = *parse_allowed_types("aabb,sphere");
                const Result<Bvh> bvh = build_budgeted(primitives, algorithm, options);
                ASSERT_TRUE(bvh.has_value()) << what;
                expect_valid(*bvh, count, what);
                expect_report_filled(report, count, what);
                const double reference_cost = cost(*bvh);
                options.report = nullptr;
                const Result<Bvh> other = build_budgeted(shuffled(primitives, count), algorithm, options);
                ASSERT_TRUE(other.has_value()) << what;
                EXPECT_NEAR(cost(*other), reference_cost, 1e-9 * std::max(1.0, reference_cost)) << what;
            }
        }
    }
}

TEST(BranchAndBoundBuilders, ValidOnBundledModels) {
    for (const auto& [name, primitives] : test_support::bundled_models()) {
        for (Algorithm algorithm : bnb_algorithms) {
            const std::string what = std::string(to_string(algorithm)) + " " + name;
            BuildReport report;
            const Result<Bvh> bvh = build_budgeted(primitives, algorithm, test_support::context_for(VolumePolicy::all(), &report));
            ASSERT_TRUE(bvh.has_value()) << what;
            expect_valid(*bvh, primitives.size(), what);
            expect_report_filled(report, primitives.size(), what);
            if (algorithm == Algorithm::bnb_tightest) continue;  // its shuffles are covered on generated scenes
            const Result<Bvh> other = build_budgeted(shuffled(primitives, 11), algorithm, BuildContext{});
            ASSERT_TRUE(other.has_value()) << what;
            EXPECT_NEAR(cost(*other), cost(*bvh), 1e-9 * cost(*bvh)) << what;
        }
    }
}

/// Opt-in survey of costs, times and candidate counts (run with --gtest_also_run_disabled_tests).
TEST(BranchAndBoundBuilders, DISABLED_PrintSurvey) {
    std::vector<std::pair<std::string, std::vector<Primitive>>> inputs = test_support::bundled_models();
    for (std::uint32_t count : {8u, 13u, 17u, 21u, 27u, 30u}) {
        SceneOptions scene;
        scene.count = count;
        scene.seed = 1000 + count;
        inputs.emplace_back("scene n=" + std::to_string(count), generate_scene(scene));
    }
    for (const auto& [name, primitives] : inputs) {
        for (Algorithm algorithm : {Algorithm::two_level, Algorithm::bnb_tightest, Algorithm::bnb_enlarge}) {
            BuildReport report;
            BuildContext options;
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
            std::printf("%-20s %-13s cost=%12.3f height=%u levels=%zu MC=%5u solver_nodes=%10llu fallbacks=%d "
                        "budget_hits=%d time=%.3fs\n",
                        name.c_str(), std::string(to_string(algorithm)).c_str(), stats.cost, stats.height, report.levels.size(),
                        report.total_candidates, static_cast<unsigned long long>(solver_nodes), fallbacks, budget_hits,
                        seconds);
        }
    }
}

}  // namespace
}  // namespace hbvh
