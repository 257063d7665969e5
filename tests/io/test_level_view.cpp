// SPDX-License-Identifier: MIT
// level_views(): each level covers every primitive; level costs add up to Eq. 2.
#include <gtest/gtest.h>

#include <algorithm>

#include "hbvh/io/level_view.hpp"
#include "hbvh/tree/stats.hpp"
#include "hbvh/tree/validate.hpp"
#include "io/sample_hierarchy.hpp"

namespace hbvh {
namespace {

TEST(LevelViews, CarryHighLeavesToEveryDeeperLevel) {
    const Bvh bvh = test::sample_hierarchy();
    ASSERT_TRUE(validate(bvh).has_value());
    const std::vector<LevelView> views = level_views(bvh);
    ASSERT_EQ(views.size(), 4u);
    EXPECT_EQ(views[0].nodes, std::vector<std::uint32_t>{0});
    EXPECT_TRUE(views[0].carried.empty());
    EXPECT_TRUE(views[1].carried.empty());
    EXPECT_EQ(views[2].carried.size(), 1u);  // the knob
    EXPECT_EQ(views[3].carried.size(), 2u);  // the knob and the lone sphere
    EXPECT_EQ(views[3].inner_count, 0u);
    EXPECT_DOUBLE_EQ(views[3].cost, 0.0);
}

TEST(LevelViews, EveryLevelCoversEveryPrimitiveOnce) {
    const Bvh bvh = test::sample_hierarchy();
    for (const LevelView& view : level_views(bvh)) {
        std::vector<std::uint32_t> covered;
        for (std::uint32_t index : view.nodes) {
            const auto below = covered_primitives(bvh, index);
            covered.insert(covered.end(), below.begin(), below.end());
        }
        for (std::uint32_t index : view.carried) {
            ASSERT_TRUE(bvh.nodes[index].is_leaf());
            covered.push_back(bvh.nodes[index].primitive);
        }
        std::sort(covered.begin(), covered.end());
        std::vector<std::uint32_t> all(bvh.primitives.size());
        for (std::uint32_t i = 0; i < all.size(); ++i) all[i] = i;
        EXPECT_EQ(covered, all) << "level " << view.depth;
    }
}

TEST(LevelViews, CostsAndVolumesAddUp) {
    const Bvh bvh = test::sample_hierarchy();
    double total_cost = 0.0, total_volume = 0.0;
    for (const LevelView& view : level_views(bvh)) {
        total_cost += view.cost;
        total_volume += view.volume;
    }
    EXPECT_NEAR(total_cost, cost(bvh), 1e-9 * cost(bvh));
    double node_volume = 0.0;
    for (const Node& node : bvh.nodes) node_volume += volume(node.volume);
    EXPECT_NEAR(total_volume, node_volume, 1e-9 * node_volume);
}

TEST(LevelViews, EmptyHierarchyHasNoLevels) { EXPECT_TRUE(level_views(Bvh{}).empty()); }

TEST(LevelColors, AreDistinctHexWithinACycle) {
    std::vector<std::string> seen;
    for (std::uint32_t depth = 0; depth < 8; ++depth) {
        const std::string hex = to_hex(level_color(depth));
        ASSERT_EQ(hex.size(), 7u);
        EXPECT_EQ(hex[0], '#');
        EXPECT_EQ(std::count(seen.begin(), seen.end(), hex), 0) << hex;
        seen.push_back(hex);
    }
    EXPECT_EQ(to_hex({1.0, 0.0, 0.5}), "#ff0080");
    EXPECT_EQ(to_hex({2.0, -1.0, 0.0}), "#ff0000");
}

}  // namespace
}  // namespace hbvh
