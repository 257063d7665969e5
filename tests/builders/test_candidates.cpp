// SPDX-License-Identifier: MIT
// The survey's candidate heuristics on hand-made levels: Tightest's growth order, Enlarge's steps,
// colliders and lg n limit, and the homothety it enlarges with.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <map>
#include <numbers>
#include <set>
#include <vector>

#include "builders/candidates.hpp"
#include "support/test_helpers.hpp"

namespace hbvh {
namespace {

using test_support::make_level;

std::set<std::vector<std::uint32_t>> normalised(std::vector<std::vector<std::uint32_t>> sets) {
    std::set<std::vector<std::uint32_t>> out;
    for (auto& s : sets) {
        std::sort(s.begin(), s.end());
        out.insert(s);
    }
    return out;
}

Primitive ball(double x, double radius) { return {Sphere{Vec3(x, 0, 0), radius}, ""}; }

TEST(TightestCandidates, GrowsByEq1FromEveryNode) {
    // Unit cubes at x = 0, 1.5, 4, 9: from node 0 the tightest partner is 1, then 2, then 3 (Fig. 10).
    std::vector<Primitive> primitives;
    for (double x : {0.0, 1.5, 4.0, 9.0}) primitives.push_back({Aabb{Vec3(x, 0, 0), Vec3(x + 1, 1, 1)}, ""});
    const Level level = make_level(primitives, VolumePolicy::only(BvType::aabb));
    const auto sets = tightest_candidates(level);
    // Start 1 reaches {0,1}, already grown through from start 0, and stops; start 2 stops at {0,1,2}.
    ASSERT_EQ(sets.size(), 6u);
    EXPECT_EQ(sets[0], (std::vector<std::uint32_t>{0, 1}));
    EXPECT_EQ(sets[1], (std::vector<std::uint32_t>{0, 1, 2}));
    EXPECT_EQ(sets[2], (std::vector<std::uint32_t>{0, 1, 2, 3}));
    // From node 3 (x = 9): nearest is node 2, then 1, then 0.
    EXPECT_EQ(sets[3], (std::vector<std::uint32_t>{1, 2}));
    EXPECT_EQ(sets[4], (std::vector<std::uint32_t>{2, 3}));
    EXPECT_EQ(sets[5], (std::vector<std::uint32_t>{1, 2, 3}));
    EXPECT_EQ(normalised(sets).size(), 6u);  // {0,1} {0,1,2} {0..3} {1,2} {1,2,3} {2,3}
}

TEST(EnlargeCandidates, MaxGroupSizeIsFloorLgNAtLeastTwo) {
    EXPECT_EQ(enlarge_max_group_size(1), 2u);
    EXPECT_EQ(enlarge_max_group_size(3), 2u);
    EXPECT_EQ(enlarge_max_group_size(7), 2u);
    EXPECT_EQ(enlarge_max_group_size(8), 3u);
    EXPECT_EQ(enlarge_max_group_size(15), 3u);
    EXPECT_EQ(enlarge_max_group_size(16), 4u);
    EXPECT_EQ(enlarge_max_group_size(27), 4u);
    EXPECT_EQ(enlarge_max_group_size(32), 5u);
}

TEST(EnlargeCandidates, ScalingAboutTheCentreKeepsKindAndScalesVolumeByCube) {
    const std::vector<BoundingVolume> volumes{
        Aabb{Vec3(0, 0, 0), Vec3(1, 2, 3)},
        Obb{Vec3(1, 1, 1), Eigen::AngleAxisd(0.3, Vec3(1, 2, 3).normalized()).toRotationMatrix(), Vec3(1, 2, 0.5)},
        Sphere{Vec3(1, 2, 3), 0.7},
        Capsule{Vec3(0, 0, 0), Vec3(2, 1, 0), 0.4},
    };
    for (const BoundingVolume& bv : volumes) {
        const BoundingVolume grown = scaled_about_center(bv, 1.25);
        EXPECT_EQ(grown.index(), bv.index());
        EXPECT_NEAR(volume(grown), std::pow(1.25, 3) * volume(bv), 1e-12 * volume(grown));
        EXPECT_TRUE((world_aabb(grown).center() - world_aabb(bv).center()).norm() < 1e-12);
        for (const Sphere& s : generating_spheres(bv)) EXPECT_TRUE(contains(grown, s, 1e-12));
    }
}

TEST(EnlargeCandidates, StopsAtTheFirstCollision) {
    // Balls of radius 1 at x = 0, 3.02, 7: node 0 needs s >= 2.02 (step 21) to reach node 1, node 1
    // reaches node 0 first, node 2 reaches node 1 first. n = 3: pairs only.
    const std::vector<Primitive> primitives{ball(0, 1), ball(3.02, 1), ball(7, 1)};
    const Level level = make_level(primitives, VolumePolicy::all());
    const auto sets = normalised(enlarge_candidates(level));
    EXPECT_EQ(sets, (std::set<std::vector<std::uint32_t>>{{0, 1}, {1, 2}}));
}

TEST(EnlargeCandidates, APassedDeadlineStopsTheGrowthTests) {
    // The growth tests every pair of nodes and fits nothing, so a deadline set on the level (which fit_group
    // throws at) went unseen: bnb-enlarge took 2.3 s at 2000 primitives and more than 100 s at 20 000 under a
    // limit of 0.3 s. Each node's tests now start with the deadline.
    const std::vector<Primitive> primitives{ball(0, 1), ball(3.02, 1), ball(7, 1)};
    Level level = make_level(primitives, VolumePolicy::all());
    level.stop_fitting_after(BuildContext::Clock::now() - std::chrono::seconds(1));
    EXPECT_THROW((void)enlarge_candidates(level), LevelDeadlinePassed);
    level.stop_fitting_after(BuildContext::Clock::time_point::max());
    EXPECT_EQ(normalised(enlarge_candidates(level)), (std::set<std::vector<std::uint32_t>>{{0, 1}, {1, 2}}));
}

TEST(EnlargeCandidates, ANodeMeetingEveryOtherOffersNoMoreSubsetsThanTheCap) {
    // 16 balls around one point: every node meets the 15 others at step 0 and offers every subset of up to
    // floor(lg 16) - 1 = 3 of them, 15 + 105 + 455 = 575. With a cap of 100 a node keeps its first 8 colliders
    // (8 + 28 + 56 = 92; 9 would make 129). 100 such spheres made 7.5e7 subsets a node, 6 GB, before the cap.
    std::vector<Primitive> primitives;
    for (int i = 0; i < 16; ++i) primitives.push_back(ball(0.01 * i, 1));
    const Level level = make_level(primitives, VolumePolicy::all());
    const auto per_node = [&](const EnlargeOptions& options) {
        std::map<std::uint32_t, std::size_t> count;
        for (const std::vector<std::uint32_t>& set : enlarge_candidates(level, options)) ++count[set.back()];
        return count;
    };
    EnlargeOptions uncapped;
    uncapped.max_subsets_per_node = 0;
    EnlargeOptions capped;
    capped.max_subsets_per_node = 100;
    const auto all = per_node(uncapped);
    const auto kept = per_node(capped);
    ASSERT_EQ(all.size(), 16u);
    ASSERT_EQ(kept.size(), 16u);
    for (std::uint32_t node = 0; node < 16; ++node) {
        EXPECT_EQ(all.at(node), 575u) << node;
        EXPECT_EQ(kept.at(node), 92u) << node;
    }
}

TEST(EnlargeCandidates, AllSubsetsOfCollidersUpToLgN) {
    // 8 balls (lg 8 = 3): node 0 overlaps nodes 1, 2, 3 as given; nodes 4..7 are far away in a row.
    std::vector<Primitive> primitives{ball(0, 1), ball(0.5, 1), ball(1.0, 1), ball(1.5, 1)};
    for (int i = 0; i < 4; ++i) primitives.push_back(ball(100 + 3 * i, 1));
    const Level level = make_level(primitives, VolumePolicy::all());
    const auto all = enlarge_candidates(level);
    std::set<std::vector<std::uint32_t>> from_zero;
    for (auto s : all) {
        std::sort(s.begin(), s.end());
        if (s.front() == 0) from_zero.insert(s);
    }
    // From node 0 (colliders 1, 2, 3 at step 0): 3 pairs + 3 triples; others' candidates may add more
    // sets containing 0, so check inclusion and sizes.
    for (const auto& s : std::vector<std::vector<std::uint32_t>>{{0, 1}, {0, 2}, {0, 3}, {0, 1, 2}, {0, 1, 3}, {0, 2, 3}})
        EXPECT_TRUE(from_zero.count(s)) << s.size();
    for (const auto& s : all) {
        EXPECT_GE(s.size(), 2u);
        EXPECT_LE(s.size(), 3u);
    }
}

TEST(EnlargeCandidates, MinCollisionsAndColliderCap) {
    const std::vector<Primitive> primitives{ball(0, 1), ball(3, 1), ball(6.5, 1), ball(11, 1)};
    const Level level = make_level(primitives, VolumePolicy::all());
    EnlargeOptions options;
    options.min_collisions = 2;
    const auto sets = normalised(enlarge_candidates(level, options));
    EXPECT_TRUE(sets.count({0, 2}));  // node 0 keeps growing past node 1 until it also reaches node 2
    options.max_colliders = 1;
    for (const auto& s : enlarge_candidates(level, options)) EXPECT_EQ(s.size(), 2u);
}

TEST(EnlargeCandidates, PointsNeverGrowAndContributeNothing) {
    // A radius-0 ball stays a point under scaling; the cap stops it and the driver's fallback covers it.
    const std::vector<Primitive> primitives{ball(0, 0), ball(5, 1), ball(8, 1)};
    const Level level = make_level(primitives, VolumePolicy::all());
    const auto sets = enlarge_candidates(level);
    EXPECT_FALSE(sets.empty());
    for (const auto& s : sets) EXPECT_TRUE(std::find(s.begin(), s.end(), 0u) == s.end());
}

}  // namespace
}  // namespace hbvh
