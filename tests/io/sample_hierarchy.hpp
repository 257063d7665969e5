// SPDX-License-Identifier: MIT
// A small unbalanced hierarchy with all four BV kinds, shared by the exporter tests.
#pragma once

#include "hbvh/scene/generate.hpp"
#include "hbvh/tree/bvh.hpp"

namespace hbvh::test {

/// Four levels: root (aabb) -> {A (sphere), leaf 4}; A -> {B (capsule), leaf 2}; B -> {leaves 0, 1, 3}.
/// Leaves 4 and 2 sit high, so levels 2 and 3 carry them. Every inner BV contains its children.
inline Bvh sample_hierarchy() {
    SplitMix64 random(7);
    std::vector<Primitive> primitives{
        {Aabb{Vec3(-1, -1, -1), Vec3(0, 0, 0)}, "block"},
        {Obb{Vec3(1, 0.5, 0), random.rotation(), Vec3(0.5, 0.3, 0.2)}, "plate"},
        {Sphere{Vec3(3, 0, 0), 0.5}, ""},
        {Capsule{Vec3(0, 1, 1), Vec3(1, 2, 1.5), 0.3}, "rod"},
        {Sphere{Vec3(6, 6, 0), 1.0}, "knob"},
    };
    TreeAssembler assembler(primitives);
    std::uint32_t leaf[5];
    for (std::uint32_t i = 0; i < 5; ++i) leaf[i] = assembler.add_leaf(i);
    const std::uint32_t b_children[] = {leaf[0], leaf[1], leaf[3]};
    const std::uint32_t b = assembler.add_group(b_children, Capsule{Vec3(-0.5, 0, 0), Vec3(0.5, 0.5, 0.5), 3.5});
    const std::uint32_t a_children[] = {b, leaf[2]};
    const std::uint32_t a = assembler.add_group(a_children, Sphere{Vec3(0.5, 0.5, 0.5), 6.0});
    const std::uint32_t root_children[] = {a, leaf[4]};
    const std::uint32_t root = assembler.add_group(root_children, Aabb{Vec3(-6, -6, -6), Vec3(7.5, 7.5, 7)});
    return std::move(assembler).finish(root);
}

}  // namespace hbvh::test
