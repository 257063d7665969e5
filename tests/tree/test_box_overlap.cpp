// SPDX-License-Identifier: MIT
// The grid behind compute_stats' sibling overlap, against the pair-by-pair sum on box sets of many shapes.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "support/tree_properties.hpp"
#include "hbvh/builders/two_level.hpp"
#include "hbvh/tree/stats.hpp"
#include "tree/box_overlap.hpp"

namespace hbvh {
namespace {

/// Every pair, as the definition reads (docs/metrics.md).
double every_pair(const std::vector<Aabb>& boxes) {
    double sum = 0.0;
    for (std::size_t i = 0; i < boxes.size(); ++i)
        for (std::size_t j = i + 1; j < boxes.size(); ++j) {
            const Vec3 lo = boxes[i].min.cwiseMax(boxes[j].min), hi = boxes[i].max.cwiseMin(boxes[j].max);
            if ((hi.array() > lo.array()).all()) sum += (hi - lo).prod();
        }
    return sum;
}

enum class Shape { uniform, clustered, with_huge_boxes, flat, coincident, sticks };

std::vector<Aabb> boxes_of(Shape shape, std::size_t count, std::uint32_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::vector<Aabb> boxes;
    for (std::size_t i = 0; i < count; ++i) {
        Vec3 centre(unit(rng) * 100.0, unit(rng) * 100.0, unit(rng) * 100.0);
        Vec3 half = Vec3(unit(rng), unit(rng), unit(rng)) * 6.0;
        switch (shape) {
            case Shape::uniform: break;
            case Shape::clustered: centre = Vec3::Constant(50.0) + (centre - Vec3::Constant(50.0)) * (i % 3 == 0 ? 0.05 : 1.0); break;
            case Shape::with_huge_boxes: if (i % 50 == 0) half *= 12.0; break;
            case Shape::flat: centre.z() = 7.0, half.z() = 0.0; break;  // every box flat in one plane: all volumes 0
            case Shape::coincident: centre = Vec3::Constant(3.0), half = Vec3(1.0, 2.0, 3.0); break;
            case Shape::sticks: half.x() *= 40.0; break;  // long along x, thin elsewhere
        }
        boxes.push_back({centre - half, centre + half});
    }
    return boxes;
}

TEST(BoxOverlap, EqualsThePairByPairSumOnEveryShape) {
    const std::pair<Shape, const char*> shapes[] = {{Shape::uniform, "uniform"},     {Shape::clustered, "clustered"},
                                                    {Shape::with_huge_boxes, "huge"}, {Shape::flat, "flat"},
                                                    {Shape::coincident, "coincident"}, {Shape::sticks, "sticks"}};
    for (const auto& [shape, name] : shapes)
        for (const std::size_t count : {2u, 40u, 65u, 300u, 2000u}) {
            SCOPED_TRACE(std::string(name) + " " + std::to_string(count));
            const std::vector<Aabb> boxes = boxes_of(shape, count, static_cast<std::uint32_t>(count) + 11);
            const double expected = every_pair(boxes);
            const double got = detail::pairwise_intersection_volume(boxes);
            EXPECT_NEAR(got, expected, 1e-12 * expected) << "expected " << expected;
            if (shape != Shape::flat && count >= 300) {
                EXPECT_GT(expected, 0.0);  // the sets do overlap
            }
        }
}

TEST(BoxOverlap, TouchingBoxesAddNothing) {
    // A 10 x 10 x 10 lattice of unit cubes sharing faces: no pair has an intersection of positive volume.
    std::vector<Aabb> boxes;
    for (int x = 0; x < 10; ++x)
        for (int y = 0; y < 10; ++y)
            for (int z = 0; z < 10; ++z) boxes.push_back({Vec3(x, y, z), Vec3(x + 1, y + 1, z + 1)});
    EXPECT_EQ(detail::pairwise_intersection_volume(boxes), 0.0);
    // Grown by a quarter on every side, each face-neighbour pair overlaps by 0.5 x 1.5 x 1.5 and the edge and
    // corner neighbours by less: the brute force says how much in all.
    for (Aabb& box : boxes) box = {box.min - Vec3::Constant(0.25), box.max + Vec3::Constant(0.25)};
    EXPECT_NEAR(detail::pairwise_intersection_volume(boxes), every_pair(boxes), 1e-12 * every_pair(boxes));
}

TEST(BoxOverlap, StatsOfAWideRootMatchTheDefinition) {
    // A two-level tree: 500 children under one root, so compute_stats takes the grid path.
    const std::vector<Primitive> primitives = test_support::generated_scene(500, 3);
    const Bvh bvh = build_two_level(primitives, BuildContext{}, {}).value();
    std::vector<Aabb> boxes;
    double sibling_volume = 0.0;
    for (const Node& child : bvh.children(bvh.root())) {
        boxes.push_back(world_aabb(child.volume));
        sibling_volume += boxes.back().volume();
    }
    ASSERT_EQ(boxes.size(), 500u);
    const double expected = every_pair(boxes) / sibling_volume;
    EXPECT_GT(expected, 0.0);
    EXPECT_NEAR(compute_stats(bvh).overlap, expected, 1e-12 * expected);
}

}  // namespace
}  // namespace hbvh
