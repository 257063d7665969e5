// SPDX-License-Identifier: MIT
// The scale builder: tree properties, thread-count independence, quality against merge/split, and auto.
#include <gtest/gtest.h>

#include <tbb/global_control.h>

#include <algorithm>
#include <numeric>
#include <optional>
#include <string>
#include <vector>

#include "support/bundled_models.hpp"
#include "support/test_helpers.hpp"
#include "hbvh/builders/binned.hpp"
#include "hbvh/builders/build.hpp"
#include "hbvh/builders/merge.hpp"
#include "hbvh/builders/scale.hpp"
#include "hbvh/builders/treelet.hpp"
#include "hbvh/scene/generate.hpp"
#include "hbvh/tree/stats.hpp"
#include "hbvh/tree/validate.hpp"
#include "support/tree_properties.hpp"

namespace hbvh {
namespace {

using test_support::expect_identical_trees;
using test_support::expect_tree_properties;
using test_support::generated_scene;

// Sizes around scale's thresholds (exact fits for all groups up to 64 primitives, refits on levels of at most
// 256 nodes), up to 1000 (nine levels, the first two above 256 nodes). A 5000 scene (clustered only) took the
// same paths again over three more levels, for about two thirds of the test's 15 s under the sanitizers.
TEST(Scale, PropertiesOnGeneratedScenes) {
    for (std::uint32_t count : {1u, 2u, 3u, 4u, 5u, 7u, 33u, 100u, 257u, 1000u}) {
        for (bool clustered : {true, false}) {
            SCOPED_TRACE(std::to_string(count) + (clustered ? " clustered" : " uniform"));
            const std::vector<Primitive> primitives = generated_scene(count, 100 + count, clustered);
            BuildReport report;
            const Bvh bvh = build_scale(primitives, test_support::context_for(VolumePolicy::all(), &report), {}).value();
            expect_tree_properties(primitives, bvh);
            if (count > 1) {
                EXPECT_FALSE(report.levels.empty());
            }
        }
    }
}

TEST(Scale, PropertiesWithRestrictedPolicies) {
    const std::vector<Primitive> primitives = generated_scene(600, 7);
    for (BvType type : all_bv_types) {
        SCOPED_TRACE(std::string(to_string(type)));
        const VolumePolicy policy = VolumePolicy::only(type);
        const Bvh bvh = build_scale(primitives, test_support::context_for(policy)).value();
        expect_tree_properties(primitives, bvh);
        for (const Node& node : bvh.nodes)
            if (!node.is_leaf()) {
                EXPECT_EQ(type_of(node.volume), type);
            }
    }
}

// Each level's windows (about 32 nodes each) are solved in parallel: 1000 primitives give about 31 windows on
// the first level, about a dozen on the second, ... (3000 took three times as long for more of the same).
TEST(Scale, SameHierarchyForOneAndTwoThreads) {
    const std::vector<Primitive> primitives = generated_scene(1000, 42);
    const auto build_with = [&](std::size_t threads) {
        const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
        return build_scale(primitives, test_support::context_for(VolumePolicy::all())).value();
    };
    expect_identical_trees(build_with(1), build_with(2));
}

// The capsule on demand: groups priced without a capsule step that may still win, and the window solved again until
// its chosen groups are priced exactly, give the covers of pricing every group exactly first (fit_best is used on
// inputs of up to 64 primitives: the bundled models and small generated scenes, boxes, spheres and capsules).
TEST(Scale, CapsuleStepsOnDemandChangeNoTree) {
    std::vector<std::pair<std::string, std::vector<Primitive>>> inputs;
    for (std::uint32_t seed = 1; seed <= 3; ++seed) inputs.emplace_back("generated", generated_scene(20 + 10 * seed, seed));
    for (auto& [name, primitives] : test_support::bundled_models()) inputs.emplace_back(name, primitives);
    ScaleOptions at_once;
    at_once.capsule_on_demand = false;
    for (const auto& [name, primitives] : inputs) {
        SCOPED_TRACE(name + " " + std::to_string(primitives.size()));
        const BuildContext context = test_support::context_for(VolumePolicy::all());
        expect_identical_trees(build_scale(primitives, context).value(), build_scale(primitives, context, at_once).value());
    }
}

// merge is beaten on every scene. split is not: its top-down cuts give 30-40 % lower Eq. 2 costs than
// scale's local bottom-up windows (docs/scale.md §4), so the ratio is recorded, not asserted. One scene: a
// second one (1500 primitives, seed 6) checked the same again and doubled the time (28 s under the
// sanitizers, half of it split's build for the recorded ratio).
TEST(Scale, NoWorseThanMergeAndRatioToSplitRecorded) {
    for (const auto& [count, seed] : {std::pair{1000u, 5u}}) {
        SCOPED_TRACE(std::to_string(count));
        const std::vector<Primitive> primitives = generated_scene(count, seed);
        const double scale_cost = cost(build_scale(primitives, test_support::context_for(VolumePolicy::all())).value());
        Result<Bvh> merged = build(primitives, Algorithm::merge);
        ASSERT_TRUE(merged.has_value());
        EXPECT_LE(scale_cost, cost(merged.value()));
        Result<Bvh> split = build(primitives, Algorithm::split);
        ASSERT_TRUE(split.has_value());
        RecordProperty("scale_over_split_" + std::to_string(count), std::to_string(scale_cost / cost(split.value())));
    }
}

TEST(Scale, ReportsProgressUpToOne) {
    std::vector<double> fractions;
    BuildContext context;
    context.progress = [&](double f) { fractions.push_back(f); };
    (void)build_scale(generated_scene(500, 3), context).value();
    ASSERT_FALSE(fractions.empty());
    for (std::size_t i = 1; i < fractions.size(); ++i) EXPECT_GE(fractions[i], fractions[i - 1]);
    EXPECT_DOUBLE_EQ(fractions.back(), 1.0);
}

TEST(Scale, TimeLimitStillGivesAValidTree) {
    const std::vector<Primitive> primitives = generated_scene(2000, 9);
    BuildReport report;
    // Past at once: no window makes groups (each still fitted its candidates for an initial cover, and 10^5
    // primitives took 4.6 s under a 0.5 s limit), and one root takes every node of the level.
    const BuildContext context = test_support::context_for(VolumePolicy::all(), &report).with_time_limit(1e-6);
    const Bvh bvh = build_scale(primitives, context).value();
    expect_tree_properties(primitives, bvh);
    EXPECT_TRUE(report.budget_hit);
    EXPECT_EQ(bvh.nodes.front().child_count, 2000u);
    EXPECT_NE(report.time_limit.find("scale: the time limit passed during level 0; one root over the 2000 nodes left"),
              std::string::npos)
        << report.time_limit;
}

TEST(Merge, ChecksItsDeadlineWhileBuildingItsGraph) {
    // merge priced every node and every first edge before its first collapse, the only place it looked at the
    // deadline: 20 000 primitives took 4-5 s under a 0.5 s limit. The checks between (which report progress too)
    // are counted here: before the first collapse there used to be one, the guard's.
    const std::vector<Primitive> primitives = generated_scene(1000, 4);
    BuildContext context;
    std::size_t before_first_collapse = 0;
    bool collapsed = false;
    context.progress = [&](double fraction) {
        collapsed = collapsed || fraction > 0.0;
        if (!collapsed) ++before_first_collapse;
    };
    ASSERT_TRUE(build_merge(primitives, context).has_value());
    EXPECT_GT(before_first_collapse, 1000u / 64u);
}

TEST(Auto, PicksBySizeAndSaysSo) {
    EXPECT_EQ(auto_choice(1), Algorithm::optimal);
    EXPECT_EQ(auto_choice(auto_optimal_max_primitives), Algorithm::optimal);
    EXPECT_EQ(auto_choice(auto_optimal_max_primitives + 1), Algorithm::insertion_haber);
    EXPECT_EQ(auto_choice(auto_merge_max_primitives), Algorithm::insertion_haber);
    EXPECT_EQ(auto_choice(auto_merge_max_primitives + 1), Algorithm::scale);
    EXPECT_EQ(auto_choice(auto_refine_each_max_primitives), Algorithm::scale);
    EXPECT_EQ(auto_choice(auto_refine_each_max_primitives + 1), Algorithm::insertion_haber);
    ASSERT_EQ(parse_algorithm("auto"), Algorithm::automatic);
    for (std::uint32_t count : {5u, auto_optimal_max_primitives + 1, auto_merge_max_primitives + 10}) {
        const std::vector<Primitive> primitives = generated_scene(count, count);
        BuildReport report;
        BuildContext options;
        options.report = &report;
        Result<Bvh> built = build(primitives, Algorithm::automatic, options);
        ASSERT_TRUE(built.has_value());
        expect_tree_properties(primitives, built.value());
        // One note names the portfolio (auto_choice is its first member) and the builder kept.
        const auto said = std::find_if(report.notes.begin(), report.notes.end(), [&](const std::string& note) {
            return note.starts_with("auto:") &&
                   note.find(std::string(to_string(auto_choice(count)))) != std::string::npos;
        });
        EXPECT_NE(said, report.notes.end()) << (report.notes.empty() ? "" : report.notes.front());
    }
}

// A member of auto's portfolio built alone, as auto builds it (binned without its net against split).
Bvh member_alone(std::span<const Primitive> primitives, Algorithm member) {
    BinnedOptions binned_alone;
    binned_alone.guarantee_split_up_to = 0;
    return member == Algorithm::binned ? build_binned(primitives, BuildContext{}, binned_alone).value()
                                       : build(primitives, member, BuildContext{}).value();
}

// The members build and refine in parallel, sharing one fit cache; the winner is picked in list order
// afterwards. With one thread or two, and against each member built and refined alone (its own cache,
// one at a time), the same tree comes out.
TEST(Auto, SameTreeForOneAndTwoThreadsAndAsTheMembersAlone) {
    for (const std::uint32_t count : {auto_optimal_max_primitives + 3}) {  // 34 s under the sanitizers with a second size
        SCOPED_TRACE(count);
        const std::vector<Primitive> primitives = generated_scene(count, 40 + count);
        const auto build_with = [&](std::size_t threads) {
            const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
            return build(primitives, Algorithm::automatic, BuildContext{}).value();
        };
        const Bvh two = build_with(2);
        test_support::expect_identical_trees(build_with(1), two);
        // The cheapest member refined alone, the first on ties, as a serial loop would find it.
        std::optional<Bvh> cheapest;
        for (const Algorithm member : auto_portfolio(count)) {
            const Bvh refined = refine_treelets(member_alone(primitives, member), VolumePolicy::all());
            if (!cheapest || cost(refined) < cost(*cheapest)) cheapest = refined;
        }
        test_support::expect_identical_trees(*cheapest, two);
    }
}

// From 33 to 200 primitives the two cheapest unrefined members are refined and the cheaper refined tree wins:
// the cheapest unrefined tree alone, refined, lost by up to 4.4 % to another member refined (the ANYmals, the
// Franka arm; docs/treelets.md §4). Checked against the members built and refined alone, on an input where that
// rule and refining only the cheapest unrefined tree give different trees.
TEST(Auto, RefinesTheTwoCheapestMembersAboveThirtyTwoPrimitives) {
    const std::uint32_t count = auto_refine_each_max_primitives + 4;
    const std::vector<Primitive> primitives = generated_scene(count, 5);
    std::vector<Bvh> members;
    for (const Algorithm member : auto_portfolio(count)) members.push_back(member_alone(primitives, member));
    std::vector<std::size_t> by_raw_cost(members.size());
    std::iota(by_raw_cost.begin(), by_raw_cost.end(), std::size_t{0});
    std::stable_sort(by_raw_cost.begin(), by_raw_cost.end(),
                     [&](std::size_t a, std::size_t b) { return cost(members[a]) < cost(members[b]); });
    // Only the two cheapest are refined here (refining them all was half the test's time under the sanitizers);
    // on a tie the member listed first in the portfolio wins.
    const std::size_t first = std::min(by_raw_cost[0], by_raw_cost[1]);
    const std::size_t second = std::max(by_raw_cost[0], by_raw_cost[1]);
    const Bvh refined_first = refine_treelets(members[first], VolumePolicy::all());
    const Bvh refined_second = refine_treelets(members[second], VolumePolicy::all());
    const Bvh& expected = cost(refined_second) < cost(refined_first) ? refined_second : refined_first;
    const Bvh& refined_cheapest = by_raw_cost[0] == first ? refined_first : refined_second;
    const Bvh automatic = build(primitives, Algorithm::automatic, BuildContext{}).value();
    test_support::expect_identical_trees(expected, automatic);
    EXPECT_LT(cost(automatic), cost(refined_cheapest)) << "this input does not tell the rules apart";
}

// auto builds its binned member without binned's net against split, because split is in the same portfolio
// wherever the net would run.
TEST(Auto, SplitIsInEveryPortfolioWhereBinnedWouldBuildIt) {
    for (std::uint32_t count = 1; count <= BinnedOptions{}.guarantee_split_up_to; ++count) {
        const std::vector<Algorithm> members = auto_portfolio(count);
        if (std::find(members.begin(), members.end(), Algorithm::binned) == members.end()) continue;
        EXPECT_NE(std::find(members.begin(), members.end(), Algorithm::split), members.end()) << count;
    }
}

// Under a time limit the portfolio's members share it: once it is used up the rest are skipped, and the
// report says so. The first member always runs, so there is a valid tree.
TEST(Auto, TimeLimitSkipsTheRestOfThePortfolio) {
    const std::vector<Primitive> primitives = generated_scene(auto_insertion_max_primitives + 50, 17);
    ASSERT_EQ(auto_portfolio(primitives.size()), (std::vector<Algorithm>{Algorithm::binned, Algorithm::split}));
    BuildReport report;
    const BuildContext options = test_support::context_for(VolumePolicy::all(), &report).with_time_limit(1e-6);
    Result<Bvh> built = build(primitives, Algorithm::automatic, options);
    ASSERT_TRUE(built.has_value());
    expect_tree_properties(primitives, built.value());
    EXPECT_TRUE(report.budget_hit);
    const auto said = std::find_if(report.notes.begin(), report.notes.end(), [](const std::string& note) {
        return note == "auto: time limit reached; skipped split";
    });
    EXPECT_NE(said, report.notes.end());
}

}  // namespace
}  // namespace hbvh
