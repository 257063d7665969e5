// SPDX-License-Identifier: MIT
// What every builder's tree must satisfy, checked the same way by every builder's tests, and the generated
// scenes those tests build over.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "hbvh/geometry/bounding_volume.hpp"
#include "hbvh/scene/generate.hpp"
#include "hbvh/tree/bvh.hpp"
#include "hbvh/tree/validate.hpp"

namespace hbvh::test_support {

/// A generated scene (hbvh generate's scenes) of `count` primitives.
inline std::vector<Primitive> generated_scene(std::uint32_t count, std::uint64_t seed, bool clustered = true) {
    SceneOptions options;
    options.count = count;
    options.seed = seed;
    options.clustered = clustered;
    return generate_scene(options);
}

/// Every primitive in exactly one leaf, no inner node with one child, every node's BV containing the
/// generating spheres of every primitive it covers (relative tolerance 1e-9 of the node's size), and
/// validate() agreeing. Failures are non-fatal, so one run reports every broken node.
inline void expect_tree_properties(const std::vector<Primitive>& primitives, const Bvh& bvh) {
    EXPECT_EQ(bvh.primitives.size(), primitives.size());
    std::vector<int> seen(primitives.size(), 0);
    for (std::uint32_t i = 0; i < bvh.nodes.size(); ++i) {
        const Node& node = bvh.nodes[i];
        if (node.is_leaf()) {
            EXPECT_LT(node.primitive, primitives.size());
            if (node.primitive < primitives.size()) ++seen[node.primitive];
            continue;
        }
        EXPECT_GE(node.child_count, 2u) << "node " << i;
        const double tolerance = 1e-9 * size_scale(node.volume);
        for (const std::uint32_t p : covered_primitives(bvh, i))
            for (const Sphere& s : generating_spheres(primitives[p].volume))
                EXPECT_TRUE(contains(node.volume, s, tolerance)) << "node " << i << " misses primitive " << p;
    }
    for (std::size_t p = 0; p < seen.size(); ++p) EXPECT_EQ(seen[p], 1) << "primitive " << p;
    const Status valid = validate(bvh);
    EXPECT_TRUE(valid.has_value()) << (valid.has_value() ? "" : valid.error().to_string());
}

/// The same kind with bit-identical numbers, field by field (-0 and +0 compare equal, NaN never does).
inline bool same_volume(const BoundingVolume& a, const BoundingVolume& b) {
    if (a.index() != b.index()) return false;
    return std::visit(Overloaded{[&](const Aabb& x) {
                                     const auto& y = std::get<Aabb>(b);
                                     return x.min == y.min && x.max == y.max;
                                 },
                                 [&](const Obb& x) {
                                     const auto& y = std::get<Obb>(b);
                                     return x.center == y.center && x.rotation == y.rotation &&
                                            x.half_extents == y.half_extents;
                                 },
                                 [&](const Sphere& x) {
                                     const auto& y = std::get<Sphere>(b);
                                     return x.center == y.center && x.radius == y.radius;
                                 },
                                 [&](const Capsule& x) {
                                     const auto& y = std::get<Capsule>(b);
                                     return x.p0 == y.p0 && x.p1 == y.p1 && x.radius == y.radius;
                                 }},
                      a);
}

/// The same tree node by node: structure, primitives, BV kinds and bit-identical BVs (what "deterministic for
/// any thread count" promises).
inline void expect_identical_trees(const Bvh& one, const Bvh& two) {
    ASSERT_EQ(one.nodes.size(), two.nodes.size());
    for (std::size_t i = 0; i < one.nodes.size(); ++i) {
        const Node& a = one.nodes[i];
        const Node& b = two.nodes[i];
        ASSERT_EQ(a.child_count, b.child_count) << "node " << i;
        ASSERT_EQ(a.first_child, b.first_child) << "node " << i;
        ASSERT_EQ(a.primitive, b.primitive) << "node " << i;
        ASSERT_EQ(a.volume.index(), b.volume.index()) << "node " << i;
        const auto sa = generating_spheres(a.volume), sb = generating_spheres(b.volume);
        ASSERT_EQ(sa.size(), sb.size()) << "node " << i;
        for (std::size_t k = 0; k < sa.size(); ++k) {
            ASSERT_EQ(sa[k].center, sb[k].center) << "node " << i;
            ASSERT_EQ(sa[k].radius, sb[k].radius) << "node " << i;
        }
    }
}

}  // namespace hbvh::test_support
