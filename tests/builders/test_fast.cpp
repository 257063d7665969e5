// SPDX-License-Identifier: MIT
// The fast builder: which nodes it refits and with what (against fit_best recomputed here and a brute-force
// ranking of the cheap tree's nodes), the size cap, the deadline, and thread-count independence. The
// registry's shared suite checks the common properties too.
#include <gtest/gtest.h>

#include <tbb/global_control.h>

#include <algorithm>
#include <string>
#include <vector>

#include "support/test_helpers.hpp"
#include "support/tree_properties.hpp"
#include "hbvh/builders/fast.hpp"
#include "hbvh/fit/fit.hpp"
#include "hbvh/tree/stats.hpp"

namespace hbvh {
namespace {

using test_support::expect_identical_trees;
using test_support::expect_tree_properties;
using test_support::generated_scene;

Bvh fast(std::span<const Primitive> primitives, const VolumePolicy& policy, FastOptions options = {},
         const BuildContext* context = nullptr) {
    Result<Bvh> bvh = build_fast(primitives, context != nullptr ? *context : test_support::context_for(policy), options);
    EXPECT_TRUE(bvh.has_value()) << (bvh ? "" : bvh.error().to_string());
    return bvh ? std::move(bvh).value() : Bvh{};
}

/// fit_best over the primitives below `node`, gathered here from the tree's child ranges.
BoundingVolume fit_best_below(const Bvh& bvh, std::uint32_t node, const VolumePolicy& policy) {
    FitInput input;
    std::vector<std::uint32_t> pending{node};
    std::vector<std::uint32_t> leaves;
    while (!pending.empty()) {
        const Node& n = bvh.nodes[pending.back()];
        pending.pop_back();
        if (n.is_leaf()) leaves.push_back(n.primitive);
        for (std::uint32_t c = 0; c < n.child_count; ++c) pending.push_back(n.first_child + c);
    }
    std::sort(leaves.begin(), leaves.end());  // fit_best's input in input order, as the builder gives it
    for (const std::uint32_t p : leaves) input.add(bvh.primitives[p].volume);
    return fit_best(input.spheres, policy, input.hint_axes);
}

TEST(Fast, RefitsExactlyTheHeaviestNodesWithFitBestWhereCheaper) {
    const VolumePolicy policy = VolumePolicy::all();
    std::uint32_t improved = 0;
    for (const std::uint64_t seed : {1u, 2u, 3u, 4u, 5u, 6u}) {
        SCOPED_TRACE("seed " + std::to_string(seed));
        const std::vector<Primitive> primitives = generated_scene(20 + 5 * static_cast<std::uint32_t>(seed), seed);
        const Bvh cheap = fast(primitives, policy, {.exact_fits = 0});
        const Bvh refined = fast(primitives, policy, {.exact_fits = 3});
        ASSERT_EQ(cheap.nodes.size(), refined.nodes.size());
        // The three inner nodes of the cheap tree with the largest children x volume, by a full sort.
        std::vector<std::pair<double, std::uint32_t>> terms;
        for (std::uint32_t i = 0; i < cheap.nodes.size(); ++i)
            if (!cheap.nodes[i].is_leaf())
                terms.emplace_back(-(cheap.nodes[i].child_count * policy.weighted_volume(cheap.nodes[i].volume)), i);
        std::sort(terms.begin(), terms.end());
        std::vector<std::uint32_t> heaviest;
        for (std::size_t k = 0; k < std::min<std::size_t>(3, terms.size()); ++k) heaviest.push_back(terms[k].second);
        for (std::uint32_t i = 0; i < cheap.nodes.size(); ++i) {
            const Node& before = cheap.nodes[i];
            const Node& after = refined.nodes[i];
            // Same shape everywhere.
            EXPECT_EQ(before.first_child, after.first_child);
            EXPECT_EQ(before.child_count, after.child_count);
            EXPECT_EQ(before.primitive, after.primitive);
            const bool is_heaviest = std::find(heaviest.begin(), heaviest.end(), i) != heaviest.end();
            const BoundingVolume expected = [&] {
                if (!is_heaviest) return before.volume;
                BoundingVolume exact = fit_best_below(cheap, i, policy);
                return policy.weighted_volume(exact) < policy.weighted_volume(before.volume) ? exact : before.volume;
            }();
            EXPECT_TRUE(test_support::same_volume(after.volume, expected)) << "node " << i << (is_heaviest ? " (refitted)" : "");
            if (is_heaviest && policy.weighted_volume(after.volume) < policy.weighted_volume(before.volume)) ++improved;
        }
        expect_tree_properties(primitives, refined);
    }
    // The refits did something: fit_best beat the cheap fit on some of the 18 nodes.
    EXPECT_GT(improved, 3u);
}

TEST(Fast, NodesOverTheCapAreNotRefitted) {
    const std::vector<Primitive> primitives = generated_scene(40, 9);
    const Bvh cheap = fast(primitives, VolumePolicy::all(), {.exact_fits = 0});
    const Bvh capped = fast(primitives, VolumePolicy::all(), {.exact_fits = 1000, .exact_fit_max_primitives = 3});
    std::uint32_t refitted = 0;
    for (std::uint32_t i = 0; i < cheap.nodes.size(); ++i) {
        const bool same = test_support::same_volume(cheap.nodes[i].volume, capped.nodes[i].volume);
        if (covered_primitives(cheap, i).size() > 3) {
            EXPECT_TRUE(same) << "node " << i << " over more than 3 primitives was refitted";
        } else if (!same) {
            ++refitted;
        }
    }
    EXPECT_GT(refitted, 0u);  // the small ones were
}

TEST(Fast, SameHierarchyForOneAndTwoThreads) {
    const std::vector<Primitive> primitives = generated_scene(300, 21);
    const auto build_with = [&](std::size_t threads) {
        const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
        return fast(primitives, VolumePolicy::all(), {.exact_fits = 8});
    };
    expect_identical_trees(build_with(1), build_with(2));
}

TEST(Fast, PropertiesOnEveryPolicy) {
    for (const char* types : {"aabb", "obb", "sphere", "capsule", "aabb,obb,sphere,capsule"})
        for (const std::uint32_t count : {1u, 2u, 3u, 30u, 500u}) {
            SCOPED_TRACE(std::string(types) + " " + std::to_string(count));
            const std::vector<Primitive> primitives = generated_scene(count, 3 + count, count % 2 == 0);
            expect_tree_properties(primitives, fast(primitives, parse_allowed_types(types).value()));
        }
}

TEST(Fast, APassedDeadlineStillGivesAValidTree) {
    const std::vector<Primitive> primitives = generated_scene(200, 4);
    BuildReport report;
    BuildContext context = test_support::context_for(VolumePolicy::all(), &report);
    context.deadline = BuildContext::Clock::now();  // already passed
    const Bvh bvh = fast(primitives, VolumePolicy::all(), {}, &context);
    expect_tree_properties(primitives, bvh);
    EXPECT_TRUE(report.budget_hit);
}

}  // namespace
}  // namespace hbvh
