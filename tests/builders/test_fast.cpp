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
#include "hbvh/fit/fit_fast.hpp"
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
        // Without the final collapse, which could dissolve different nodes of the two trees.
        const Bvh cheap = fast(primitives, policy, {.exact_fits = 0, .collapse = false});
        const Bvh refined = fast(primitives, policy, {.exact_fits = 3, .collapse = false});
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

/// fit_fast over the primitives below `node` with the distinct box frames and capsules among them as hints,
/// gathered here independently of the builder.
BoundingVolume fit_fast_below(const Bvh& bvh, std::uint32_t node, const VolumePolicy& policy) {
    std::vector<std::uint32_t> leaves = covered_primitives(bvh, node);
    std::sort(leaves.begin(), leaves.end());
    std::vector<Sphere> spheres;
    std::vector<BoundingVolume> hints;
    for (const std::uint32_t p : leaves) {
        const BoundingVolume& volume = bvh.primitives[p].volume;
        append_generating_spheres(volume, spheres);
        bool seen = false;
        for (const BoundingVolume& hint : hints) {
            const Obb* a = std::get_if<Obb>(&hint);
            const Obb* b = std::get_if<Obb>(&volume);
            const Capsule* c = std::get_if<Capsule>(&hint);
            const Capsule* d = std::get_if<Capsule>(&volume);
            if (a && b && (a->rotation - b->rotation).cwiseAbs().maxCoeff() < 1e-9) seen = true;
            if (c && d && c->p0 == d->p0 && c->p1 == d->p1) seen = true;
        }
        if (!seen && (std::holds_alternative<Obb>(volume) || std::holds_alternative<Capsule>(volume))) hints.push_back(volume);
    }
    return fit_fast(spheres, hints, policy);
}

TEST(Fast, QuickTreeletsOnlyLowerTheCostAndPriceNewNodesByFitFast) {
    const VolumePolicy policy = VolumePolicy::all();
    std::uint32_t rearranged = 0;
    for (const std::uint64_t seed : {11u, 12u, 13u, 14u, 15u, 16u}) {
        SCOPED_TRACE("seed " + std::to_string(seed));
        const std::vector<Primitive> primitives = generated_scene(12 + 6 * static_cast<std::uint32_t>(seed - 10), seed);
        const Bvh cheap = fast(primitives, policy, {.treelet_units = 0, .exact_fits = 0});
        const Bvh swept = fast(primitives, policy, {.treelet_units = 5, .exact_fits = 0});
        expect_tree_properties(primitives, swept);
        const double before = cost(cheap, policy);
        const double after = cost(swept, policy);
        EXPECT_LE(after, before);
        if (after < before) ++rearranged;
        // Every inner node of the swept tree is a node of the cheap tree over the same primitives with its
        // volume, or a new node whose volume is fit_fast's over its primitives (where the treelet's node
        // kept the old one, that one is no larger).
        std::vector<std::vector<std::uint32_t>> cheap_sets;
        for (std::uint32_t i = 0; i < cheap.nodes.size(); ++i) {
            std::vector<std::uint32_t> set = covered_primitives(cheap, i);
            std::sort(set.begin(), set.end());
            cheap_sets.push_back(std::move(set));
        }
        for (std::uint32_t i = 0; i < swept.nodes.size(); ++i) {
            if (swept.nodes[i].is_leaf()) continue;
            std::vector<std::uint32_t> set = covered_primitives(swept, i);
            std::sort(set.begin(), set.end());
            const auto old = std::find(cheap_sets.begin(), cheap_sets.end(), set);
            const bool kept = old != cheap_sets.end() &&
                              test_support::same_volume(swept.nodes[i].volume,
                                                        cheap.nodes[static_cast<std::size_t>(old - cheap_sets.begin())].volume);
            const bool fitted = test_support::same_volume(swept.nodes[i].volume, fit_fast_below(swept, i, policy));
            EXPECT_TRUE(kept || fitted) << "node " << i;
        }
    }
    EXPECT_GT(rearranged, 2u);  // the sweep did something on most of the six
}

TEST(Fast, NoQuickTreeletsAboveTheirCap) {
    const std::vector<Primitive> primitives = generated_scene(40, 8);
    const Bvh without = fast(primitives, VolumePolicy::all(), {.treelet_units = 0});
    expect_identical_trees(without, fast(primitives, VolumePolicy::all(), {.treelet_max_primitives = 39}));
    EXPECT_LT(cost(fast(primitives, VolumePolicy::all()), VolumePolicy::all()), cost(without, VolumePolicy::all()));
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
    for (const std::uint32_t count : {40u, 300u}) {  // with the quick treelets (up to 48), and above their cap
        const std::vector<Primitive> primitives = generated_scene(count, 21);
        const auto build_with = [&](std::size_t threads) {
            const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
            return fast(primitives, VolumePolicy::all(), {.exact_fits = 8});
        };
        expect_identical_trees(build_with(1), build_with(2));
    }
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
