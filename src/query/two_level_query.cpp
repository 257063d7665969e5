// SPDX-License-Identifier: MIT
// The survey's Two-Level query (§6): the roots, then every primitive pair.
#include "hbvh/query/tandem_traversal.hpp"
#include "pair_tests.hpp"
#include "sort_pairs.hpp"
#include "../simd/wide_clones.hpp"

namespace hbvh {

// Compiled as collide() is (an AVX2 copy with the leaf tests inlined), so that the two queries are compared on
// equal terms.
HBVH_WIDE_CLONES_INLINED void collide_two_level(const QueryTree& a, const RigidTransform& pose_a, const QueryTree& b,
                                                const RigidTransform& pose_b, CollideMode mode, CollideResult& result) {
    detail::reset(result);
    if (!detail::poses_valid(pose_a, pose_b, result) || a.empty() || b.empty()) return;
    const RigidTransform t = relative_transform(pose_a, pose_b);
    const std::span<const QueryNode> na = a.nodes(), nb = b.nodes();
    detail::MovedLeaves& moved = detail::moved_leaves();
    moved.begin(b, t);
    if (na[0].child_count == 0 && nb[0].child_count == 0) {  // two lone primitives: the root test is exact
        ++result.primitive_tests;
        if (detail::leaves_overlap(a, 0, b, 0, moved.center(0), moved)) {
            result.nodes_visited = 1;
            result.intersecting = true;
            result.pairs.emplace_back(na[0].primitive, nb[0].primitive);
        }
        return;
    }
    ++result.bv_tests;
    if (!detail::roots_overlap(a, b, t, detail::query_slack(a, b, t, t.inverse()))) return;
    result.nodes_visited = 1;
    // Every primitive pair, each of b's primitives moved once, with the same leaf test as tandem traversal
    // so that the comparison measures the hierarchy, not the pair test.
    for (const std::uint32_t leaf_b : b.primitive_nodes()) {
        const Vec3 center_b = moved.center(leaf_b);
        for (const std::uint32_t leaf_a : a.primitive_nodes()) {
            ++result.primitive_tests;
            if (!detail::leaves_overlap(a, leaf_a, b, leaf_b, center_b, moved)) continue;
            result.intersecting = true;
            result.pairs.emplace_back(na[leaf_a].primitive, nb[leaf_b].primitive);
            if (mode == CollideMode::first) return;
        }
    }
    detail::sort_pairs(result.pairs, static_cast<std::uint32_t>(a.primitive_nodes().size()),
                       static_cast<std::uint32_t>(b.primitive_nodes().size()));
}

CollideResult collide_two_level(const QueryTree& a, const RigidTransform& pose_a, const QueryTree& b,
                                const RigidTransform& pose_b, CollideMode mode) {
    CollideResult result;
    collide_two_level(a, pose_a, b, pose_b, mode, result);
    return result;
}

CollideResult collide_two_level(const Bvh& a, const RigidTransform& pose_a, const Bvh& b,
                                const RigidTransform& pose_b, CollideMode mode) {
    return detail::on_query_trees(a, b, [&](const QueryTree& ta, const QueryTree& tb) {
        return collide_two_level(ta, pose_a, tb, pose_b, mode);
    });
}

}  // namespace hbvh
