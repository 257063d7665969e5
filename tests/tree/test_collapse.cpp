// SPDX-License-Identifier: MIT
// The Eq. 2-optimal collapse of a finished tree against brute force over every subset of dissolved nodes, on the
// trees of several builders and policies, and on the degenerate input that motivated it.
#include <gtest/gtest.h>

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "../../src/tree/collapse.hpp"
#include "support/test_helpers.hpp"
#include "support/tree_properties.hpp"
#include "hbvh/builders/build.hpp"
#include "hbvh/tree/stats.hpp"

namespace hbvh {
namespace {

using test_support::expect_tree_properties;
using test_support::generated_scene;

/// The least Eq. 2 cost of any tree made from `bvh` by dissolving a subset of its non-root inner nodes, every
/// subset tried: a kept node's children are its own, each dissolved one replaced by its kept pieces.
double brute_force(const Bvh& bvh, const VolumePolicy& policy) {
    std::vector<std::uint32_t> inner;
    for (std::uint32_t i = 1; i < bvh.nodes.size(); ++i)
        if (!bvh.nodes[i].is_leaf()) inner.push_back(i);
    EXPECT_LE(inner.size(), 18u);
    std::vector<bool> dissolved(bvh.nodes.size(), false);
    const std::function<std::uint32_t(std::uint32_t)> pieces = [&](std::uint32_t node) -> std::uint32_t {
        std::uint32_t count = 0;
        for (const Node& child : bvh.children(bvh.nodes[node])) {
            const auto index = static_cast<std::uint32_t>(&child - bvh.nodes.data());
            count += dissolved[index] ? pieces(index) : 1;
        }
        return count;
    };
    double best = std::numeric_limits<double>::infinity();
    for (std::uint32_t mask = 0; mask < (1u << inner.size()); ++mask) {
        for (std::size_t b = 0; b < inner.size(); ++b) dissolved[inner[b]] = (mask >> b & 1) != 0;
        double total = 0.0;
        for (std::uint32_t i = 0; i < bvh.nodes.size(); ++i)
            if (!bvh.nodes[i].is_leaf() && !dissolved[i]) total += pieces(i) * policy.weighted_volume(bvh.nodes[i].volume);
        best = std::min(best, total);
    }
    return best;
}

TEST(Collapse, IsTheBestOfEverySubsetOfDissolvedNodes) {
    const VolumePolicy cheap_capsules = parse_type_weights("capsule=0.6,sphere=1.3").value();
    int lowered = 0, cases = 0;
    for (const Algorithm algorithm : {Algorithm::split, Algorithm::insertion, Algorithm::merge, Algorithm::obb_tree,
                                      Algorithm::binned, Algorithm::scale})
        for (std::uint32_t seed = 1; seed <= 4; ++seed)
            for (const VolumePolicy& policy : {VolumePolicy::all(), cheap_capsules}) {
                const std::vector<Primitive> primitives = generated_scene(9 + seed * 2, 40 + seed, seed % 2 == 0);
                const Result<Bvh> built = build(primitives, algorithm, test_support::context_for(policy));
                ASSERT_TRUE(built.has_value());
                std::uint32_t inner = 0;
                for (std::size_t i = 1; i < built->nodes.size(); ++i) inner += built->nodes[i].is_leaf() ? 0 : 1;
                if (inner > 18) continue;
                SCOPED_TRACE(std::string(algorithm.name()) + " seed " + std::to_string(seed));
                const Bvh collapsed = detail::collapse_optimally(*built, policy);
                expect_tree_properties(primitives, collapsed);
                const double expected = brute_force(*built, policy);
                EXPECT_NEAR(cost(collapsed, policy), expected, 1e-12 * expected);
                EXPECT_LE(cost(collapsed, policy), cost(*built, policy) * (1.0 + 1e-12));
                if (cost(collapsed, policy) < cost(*built, policy) * (1.0 - 1e-9)) ++lowered;
                ++cases;
            }
    EXPECT_GT(cases, 20);
    EXPECT_GT(lowered, 0);
}

// 300 copies of one sphere: every node's volume is the sphere's, so every inner node below the root costs its
// children's slots again, and the best tree is the flat one.
TEST(Collapse, CopiesOfOneSphereBecomeOneLevel) {
    const std::vector<Primitive> copies(300, Primitive{Sphere{Vec3(0.5, -2.0, 1.0), 0.75}, ""});
    const VolumePolicy policy = VolumePolicy::all();
    for (const Algorithm algorithm : {Algorithm::split, Algorithm::binned, Algorithm::insertion}) {
        SCOPED_TRACE(std::string(algorithm.name()));
        const Result<Bvh> built = build(copies, algorithm, test_support::context_for(policy));
        ASSERT_TRUE(built.has_value());
        const Bvh collapsed = detail::collapse_optimally(*built, policy);
        expect_tree_properties(copies, collapsed);
        EXPECT_EQ(collapsed.root().child_count, 300u);
        EXPECT_DOUBLE_EQ(cost(collapsed, policy), 300.0 * policy.weighted_volume(built->root().volume));
    }
}

TEST(Collapse, LeavesAndSmallTreesPassThrough) {
    const std::vector<Primitive> one{{Sphere{Vec3(0, 0, 0), 1.0}, ""}};
    const Result<Bvh> single = build(one, Algorithm::split, test_support::context_for(VolumePolicy::all()));
    ASSERT_TRUE(single.has_value());
    EXPECT_EQ(detail::collapse_optimally(*single, VolumePolicy::all()).nodes.size(), 1u);
    const std::vector<Primitive> two = generated_scene(2, 9);
    const Result<Bvh> pair = build(two, Algorithm::split, test_support::context_for(VolumePolicy::all()));
    ASSERT_TRUE(pair.has_value());
    const Bvh collapsed = detail::collapse_optimally(*pair, VolumePolicy::all());
    EXPECT_EQ(collapsed.nodes.size(), 3u);
    EXPECT_EQ(cost(collapsed), cost(*pair));
}

}  // namespace
}  // namespace hbvh
