// SPDX-License-Identifier: MIT
// The binned builder: its collapse against brute force, thread-count independence, bounded depth on
// adversarial input, and degenerate scenes. The registry's shared suite checks the common properties too.
#include <gtest/gtest.h>

#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "support/test_helpers.hpp"
#include "hbvh/builders/binned.hpp"
#include "hbvh/builders/split.hpp"
#include "hbvh/tree/stats.hpp"
#include "hbvh/fit/volume_policy.hpp"
#include "support/bundled_models.hpp"
#include "support/tree_properties.hpp"

namespace hbvh {
namespace {

using test_support::expect_identical_trees;
using test_support::expect_tree_properties;
using test_support::generated_scene;

VolumePolicy boxes_only() { return parse_allowed_types("aabb").value(); }

/// binned's own tree, without its net against split (which small inputs would otherwise get): these tests are
/// about its cuts, collapse and fits.
BinnedOptions own_tree() {
    BinnedOptions options;
    options.guarantee_split_up_to = 0;
    return options;
}

Bvh binned(std::span<const Primitive> primitives, const VolumePolicy& policy, BinnedOptions options = own_tree()) {
    Result<Bvh> bvh = build_binned(primitives, test_support::context_for(policy), options);
    EXPECT_TRUE(bvh.has_value()) << (bvh ? "" : bvh.error().to_string());
    return bvh ? std::move(bvh).value() : Bvh{};
}

/// The least Eq. 2 cost (AABB volumes) of any tree made from `binary` by dissolving some of its inner nodes
/// into their parents, with at most `max_children` children per node: every subset of the non-root inner
/// nodes, tried one by one.
double brute_force_collapse(const Bvh& binary, std::uint32_t max_children) {
    std::vector<std::uint32_t> inner;  // non-root inner nodes
    for (std::uint32_t i = 1; i < binary.nodes.size(); ++i)
        if (!binary.nodes[i].is_leaf()) inner.push_back(i);
    EXPECT_LE(inner.size(), 16u);
    std::vector<bool> dissolved(binary.nodes.size(), false);
    double best = std::numeric_limits<double>::infinity();
    for (std::uint32_t mask = 0; mask < (1u << inner.size()); ++mask) {
        for (std::size_t b = 0; b < inner.size(); ++b) dissolved[inner[b]] = (mask >> b & 1) != 0;
        bool fits = true;
        double total = 0.0;
        // A kept node's children: its binary children, each dissolved one replaced by its own children.
        std::function<std::uint32_t(std::uint32_t)> pieces = [&](std::uint32_t node) -> std::uint32_t {
            std::uint32_t count = 0;
            for (std::uint32_t c = binary.nodes[node].first_child; c < binary.nodes[node].first_child + binary.nodes[node].child_count; ++c)
                count += dissolved[c] ? pieces(c) : 1;
            return count;
        };
        for (std::uint32_t i = 0; i < binary.nodes.size(); ++i) {
            if (binary.nodes[i].is_leaf() || dissolved[i]) continue;
            const std::uint32_t children = pieces(i);
            if (children > max_children) fits = false;
            total += children * std::get<Aabb>(binary.nodes[i].volume).volume();
        }
        if (fits) best = std::min(best, total);
    }
    return best;
}

// With only AABBs allowed, every binary node's volume is its box, which is what the collapse prices, so the
// wide tree's cost must be the least any collapse of the binary tree (max_children = 2) can reach.
TEST(Binned, CollapseIsTheBestOfEverySubsetOfTheBinaryTree) {
    std::uint32_t collapsed = 0;  // cases where the best tree is not the binary one
    for (std::uint32_t seed = 1; seed <= 6; ++seed)
        for (const std::uint32_t max_children : {3u, 4u, 8u}) {
            const std::vector<Primitive> primitives = generated_scene(12 + seed % 3, 70 + seed, seed % 2 == 0);
            SCOPED_TRACE("seed " + std::to_string(seed) + ", max_children " + std::to_string(max_children));
            BinnedOptions binary_options = own_tree();
            binary_options.max_children = 2;
            const Bvh binary = binned(primitives, boxes_only(), binary_options);
            for (const Node& node : binary.nodes) ASSERT_TRUE(node.is_leaf() || node.child_count == 2);
            BinnedOptions wide_options = own_tree();
            wide_options.max_children = max_children;
            const Bvh wide = binned(primitives, boxes_only(), wide_options);
            expect_tree_properties(primitives, wide);
            for (const Node& node : wide.nodes) EXPECT_LE(node.child_count, max_children);
            const double expected = brute_force_collapse(binary, max_children);
            EXPECT_NEAR(cost(wide), expected, 1e-12 * expected);
            if (wide.nodes.size() < binary.nodes.size()) ++collapsed;
        }
    EXPECT_GT(collapsed, 3u);
}

TEST(Binned, SameHierarchyForOneAndTwoThreads) {
    // Above the 4096 primitives from which ranges are cut and fitted by parallel tasks.
    const std::vector<Primitive> primitives = generated_scene(9000, 17);
    const auto build_with = [&](std::size_t threads) {
        const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
        return binned(primitives, VolumePolicy::all());
    };
    expect_identical_trees(build_with(1), build_with(2));
}

TEST(Binned, PropertiesOnGeneratedScenesEveryPolicy) {
    for (const char* types : {"aabb", "obb", "sphere", "capsule", "aabb,obb,sphere,capsule"})
        for (const std::uint32_t count : {1u, 2u, 3u, 17u, 300u, 2500u}) {
            SCOPED_TRACE(std::string(types) + " " + std::to_string(count));
            const std::vector<Primitive> primitives = generated_scene(count, 5 + count, count % 2 == 0);
            BinnedOptions options = own_tree();
            options.hull_fit_min_primitives = 64;  // so that 2500 primitives reach both kinds of hull fit
            options.hull_fit_max_primitives = 512;
            options.exact_fit_max_primitives = 2;
            const Bvh bvh = binned(primitives, parse_allowed_types(types).value(), options);
            expect_tree_properties(primitives, bvh);
        }
}

// Centres at 1.5^i: each range's best binned cut splits off one primitive, so without the depth limit the
// binary tree would be a chain of 3000 nodes (and the recursion as deep).
TEST(Binned, DepthStaysLogarithmicOnAChainOfScales) {
    std::vector<Primitive> primitives;
    for (int i = 0; i < 3000; ++i) {
        const double x = std::pow(1.5, i % 1500) * (i < 1500 ? 1.0 : -1.0);
        primitives.push_back({Sphere{Vec3(x, 0.0, 0.0), 0.25}, ""});
    }
    const Bvh bvh = binned(primitives, VolumePolicy::all());
    expect_tree_properties(primitives, bvh);
    const double bound = 3.0 * std::log2(3000.0) + 32.0 + 16.0;  // the limit, then median cuts, then the sweep
    std::vector<std::uint32_t> depth(bvh.nodes.size(), 0);
    std::uint32_t height = 0;
    for (std::uint32_t i = 0; i < bvh.nodes.size(); ++i) {  // breadth-first: parents come before children
        height = std::max(height, depth[i]);
        for (std::uint32_t c = 0; c < bvh.nodes[i].child_count; ++c) depth[bvh.nodes[i].first_child + c] = depth[i] + 1;
    }
    EXPECT_LE(height, bound);
}

// Up to guarantee_split_up_to primitives the result is the cheaper of binned's own tree and split's, and beyond it
// binned's own. The tie interceptor is a model where split's tree is the cheaper (docs/scale.md §9), so both
// branches are taken.
TEST(Binned, NeverCostlierThanSplitUpToItsLimit) {
    std::vector<std::pair<std::string, std::vector<Primitive>>> inputs = test_support::bundled_models();
    for (const std::uint32_t count : {5u, 30u, 64u, 65u})
        inputs.emplace_back("generated " + std::to_string(count), generated_scene(count, count));
    const std::uint32_t limit = BinnedOptions{}.guarantee_split_up_to;
    int split_kept = 0, own_kept = 0;
    for (const auto& [name, primitives] : inputs) {
        SCOPED_TRACE(name);
        const VolumePolicy policy = VolumePolicy::all();
        const Bvh netted = binned(primitives, policy, BinnedOptions{});
        const Bvh own = binned(primitives, policy);
        expect_tree_properties(primitives, netted);
        if (primitives.size() > limit) {
            EXPECT_EQ(cost(netted), cost(own));
            continue;
        }
        const Result<Bvh> split = build_split(primitives, test_support::context_for(policy));
        ASSERT_TRUE(split.has_value());
        EXPECT_EQ(cost(netted), std::min(cost(own), cost(*split)));
        (cost(*split) < cost(own) ? split_kept : own_kept) += 1;
    }
    EXPECT_GT(split_kept, 0);
    EXPECT_GT(own_kept, 0);
}

/// binned's own tree with box-priced cuts (no estimate sweeps, as in `fast`) and the root's look-ahead over
/// `candidates` cuts (0: the greedy cut alone).
BinnedOptions looking_ahead(std::uint32_t candidates, std::uint32_t max_children) {
    BinnedOptions options = own_tree();
    options.estimate_sweep_up_to = 0;
    options.lookahead_depth = candidates > 0 ? 1 : 0;
    options.lookahead_candidates = candidates;
    options.max_children = max_children;
    return options;
}

/// Box volume of the primitives `members` (input indices).
double box_volume_of(std::span<const Primitive> primitives, std::span<const std::uint32_t> members) {
    Aabb box = Aabb::empty();
    for (const std::uint32_t i : members) box = box.merged(world_aabb(primitives[i].volume));
    return box.volume();
}

/// The primitives `members` (input indices), in input order.
std::vector<Primitive> subset(std::span<const Primitive> primitives, std::vector<std::uint32_t> members) {
    std::sort(members.begin(), members.end());
    std::vector<Primitive> out;
    for (const std::uint32_t i : members) out.push_back(primitives[i]);
    return out;
}

// With AABBs only and binary nodes (max_children 2) a tree's cost is the sum of twice each inner node's box volume,
// so the tree of a root cut is 2 x the root's volume plus the trees of its sides, each of which binned builds
// alone exactly as it plans it inside the whole (a range's cuts depend on its primitives only). The look-ahead must
// return the cheapest such tree among its candidates: the greedy cut and the local minima of the sweep's price
// along each axis, both recomputed here from the price's definition (2 log2 n x box volume per side), each side's
// tree built by a separate call.
TEST(Binned, LookAheadKeepsTheCheapestTreeAmongItsCandidateCuts) {
    int improved = 0;
    for (std::uint32_t seed = 1; seed <= 12; ++seed) {
        const std::uint32_t count = 6 + 5 * seed;  // 11 .. 66: sweeps, binned cuts and (66) no look-ahead at all
        const std::vector<Primitive> primitives = generated_scene(count, 300 + seed, seed % 3 == 0);
        SCOPED_TRACE("seed " + std::to_string(seed) + ", " + std::to_string(count) + " primitives");
        const Bvh greedy = binned(primitives, boxes_only(), looking_ahead(0, 2));
        const Bvh ahead = binned(primitives, boxes_only(), looking_ahead(64, 2));
        expect_tree_properties(primitives, ahead);
        if (count > 64) {
            expect_identical_trees(greedy, ahead);
            continue;
        }
        auto side_cost = [&](const std::vector<std::uint32_t>& members) {
            return members.size() == 1 ? 0.0 : cost(binned(subset(primitives, members), boxes_only(), looking_ahead(0, 2)));
        };
        std::vector<std::uint32_t> all(count);
        for (std::uint32_t i = 0; i < count; ++i) all[i] = i;
        const double root = 2.0 * box_volume_of(primitives, all);
        std::vector<double> candidates{cost(greedy)};
        for (int axis = 0; axis < 3; ++axis) {
            std::vector<std::uint32_t> order = all;
            std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
                return world_aabb(primitives[a].volume).center()[axis] < world_aabb(primitives[b].volume).center()[axis];
            });
            std::vector<double> price(count, 0.0);
            for (std::uint32_t left = 1; left < count; ++left) {
                const std::span<const std::uint32_t> sorted(order);
                price[left] = 2.0 * std::log2(left) * box_volume_of(primitives, sorted.first(left)) +
                              2.0 * std::log2(count - left) * box_volume_of(primitives, sorted.subspan(left));
            }
            for (std::uint32_t left = 1; left < count; ++left) {
                const bool minimum = (left == 1 || price[left] <= price[left - 1]) && (left + 1 == count || price[left] < price[left + 1]);
                if (!minimum) continue;
                const std::vector<std::uint32_t> low(order.begin(), order.begin() + left), high(order.begin() + left, order.end());
                candidates.push_back(root + side_cost(low) + side_cost(high));
            }
        }
        const double best = *std::min_element(candidates.begin(), candidates.end());
        EXPECT_NEAR(cost(ahead), best, 1e-12 * best);
        if (cost(ahead) < cost(greedy) * (1.0 - 1e-9)) ++improved;
    }
    EXPECT_GE(improved, 3);
}

// Wide nodes too (the collapse prices every kept node by its box, which is its volume here): the look-ahead's
// choice is priced with the collapse, so its tree is never dearer than the greedy cut's, whatever the candidates.
TEST(Binned, LookAheadIsNeverDearerThanTheGreedyCutUnderBoxes) {
    int improved = 0;
    for (std::uint32_t seed = 1; seed <= 20; ++seed)
        for (const std::uint32_t candidates : {1u, 6u})
            for (const std::uint32_t max_children : {4u, 8u}) {
                const std::uint32_t count = 8 + (seed * 7) % 57;
                const std::vector<Primitive> primitives = generated_scene(count, 500 + seed, seed % 2 == 0);
                SCOPED_TRACE("seed " + std::to_string(seed) + ", candidates " + std::to_string(candidates) +
                             ", max_children " + std::to_string(max_children));
                const Bvh greedy = binned(primitives, boxes_only(), looking_ahead(0, max_children));
                const Bvh ahead = binned(primitives, boxes_only(), looking_ahead(candidates, max_children));
                expect_tree_properties(primitives, ahead);
                EXPECT_LE(cost(ahead), cost(greedy) * (1.0 + 1e-12));
                if (cost(ahead) < cost(greedy) * (1.0 - 1e-9)) ++improved;
            }
    EXPECT_GE(improved, 5);
}

// Equal centres and zero volumes, where every cut prices the same: the look-ahead still gives a valid tree.
TEST(Binned, LookAheadOnCoincidentAndFlatInputs) {
    const std::vector<Primitive> coincident(40, Primitive{Sphere{Vec3(1, 2, 3), 0.5}, ""});
    expect_tree_properties(coincident, binned(coincident, VolumePolicy::all(), looking_ahead(6, 8)));
    std::vector<Primitive> flat;
    for (int i = 0; i < 50; ++i) flat.push_back({Aabb{Vec3(i % 7, i / 7, 0.0), Vec3(i % 7 + 0.5, i / 7 + 0.5, 0.0)}, ""});
    expect_tree_properties(flat, binned(flat, boxes_only(), looking_ahead(6, 8)));
    expect_tree_properties(flat, binned(flat, VolumePolicy::all(), looking_ahead(6, 5)));
}

TEST(Binned, CoincidentAndFlatScenes) {
    std::vector<Primitive> coincident(600, Primitive{Sphere{Vec3(1, 2, 3), 0.5}, ""});
    expect_tree_properties(coincident, binned(coincident, VolumePolicy::all()));
    std::vector<Primitive> flat;
    for (int i = 0; i < 700; ++i)
        flat.push_back({Aabb{Vec3(i % 30, i / 30, 0.0), Vec3(i % 30 + 0.5, i / 30 + 0.5, 0.0)}, ""});
    const Bvh bvh = binned(flat, boxes_only());
    expect_tree_properties(flat, bvh);
    // Zero volume everywhere: the cuts fall back on the boxes' areas, so the tree is still a spatial one
    // (a node's box is far smaller than the root's), not an arbitrary split.
    const Aabb root = std::get<Aabb>(bvh.nodes[0].volume);
    const Node& child = bvh.nodes[bvh.nodes[0].first_child];
    const Aabb& child_box = std::get<Aabb>(child.volume);
    EXPECT_LT((child_box.max - child_box.min).head<2>().prod(), 0.75 * (root.max - root.min).head<2>().prod());
}

}  // namespace
}  // namespace hbvh
