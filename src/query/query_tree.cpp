// SPDX-License-Identifier: MIT
// QueryTree: the read-only layout queries run on, converted once from a Bvh.
#include <algorithm>

#include "../fit/frames.hpp"
#include "hbvh/assert.hpp"
#include "hbvh/query/tandem_traversal.hpp"
#include "hbvh/tree/validate.hpp"

namespace hbvh {
namespace {

// Stand-ins are padded so that rounding can never make a pre-test reject a pair the exact test would
// accept: rounding in the radius (relative to it), and in the centre, which a transform moves with an
// error of a few ulps of its coordinates (a radius-1 sphere at 1e5 lands ~2e-11 off). The pad, 1e-12 of
// radius + |centre|_1, dominates both and the exact tests' own slacks (<= 1e-13 of the coordinates,
// geometry/overlap.cpp).
constexpr double stand_in_padding = 1e-12;

// The traversal reads one node per test: keep it compact (docs/queries.md, "Query layout").
static_assert(sizeof(QueryNode) == 160);

/// The sphere and box stand-ins of `bv` (not the smallest; cheap and tight enough to reject).
void set_stand_ins(const BoundingVolume& bv, QueryNode& q) {
    q.rotation = Mat3::Identity();
    q.axis_aligned = true;
    switch (bv.index()) {
        case 0: {
            const Aabb& box = *std::get_if<Aabb>(&bv);
            q.center = box.center();
            q.half_extents = box.half_extents();
            q.sphere_radius = q.half_extents.norm();
            break;
        }
        case 1: {
            const Obb& box = *std::get_if<Obb>(&bv);
            q.center = box.center;
            q.rotation = box.rotation;
            q.axis_aligned = false;
            q.half_extents = box.half_extents;
            q.sphere_radius = box.half_extents.norm();
            break;
        }
        case 2: {
            const Sphere& s = *std::get_if<Sphere>(&bv);
            q.center = s.center;
            q.half_extents = Vec3::Constant(s.radius);
            q.sphere_radius = s.radius;
            break;
        }
        default: {
            const Capsule& c = *std::get_if<Capsule>(&bv);
            const double half_length = 0.5 * c.length();
            q.center = c.center();
            // The box along the segment: x on the axis, half extents (L/2 + r, r, r).
            if (half_length > 0.0) {
                q.rotation = detail::frame_from_axis(c.p1 - c.p0);
                q.axis_aligned = false;
            }
            q.half_extents = Vec3(half_length + c.radius, c.radius, c.radius);
            q.sphere_radius = half_length + c.radius;
            break;
        }
    }
    const double pad = stand_in_padding * (q.sphere_radius + q.center.cwiseAbs().sum());
    q.sphere_radius += pad;
    q.half_extents.array() += pad;
}

}  // namespace

QueryTree::Checked QueryTree::checked_or_throw(const Bvh& bvh) {
    if (Status structure = check_structure(bvh); !structure) throw InvalidHierarchy(structure.error());
    return Checked{};
}

QueryTree::QueryTree(const Bvh& bvh) : QueryTree(bvh, checked_or_throw(bvh)) {}

Result<QueryTree> QueryTree::create(const Bvh& bvh) {
    if (Status structure = check_structure(bvh); !structure) return structure.error();
    return QueryTree(bvh, Checked{});
}

QueryTree::QueryTree(const Bvh& bvh, Checked) {
    nodes_.reserve(bvh.nodes.size());
    volumes_.reserve(bvh.nodes.size());
    primitive_nodes_.assign(bvh.primitives.size(), 0);
    std::vector<std::uint32_t> path_sum(bvh.nodes.size(), 0);
    for (std::uint32_t i = 0; i < bvh.nodes.size(); ++i) {
        const Node& node = bvh.nodes[i];
        QueryNode q;
        set_stand_ins(node.volume, q);
        q.measure = hbvh::volume(node.volume);
        q.first_child = node.first_child;
        q.child_count = node.child_count;
        q.primitive = node.primitive;
        q.type = type_of(node.volume);
        coordinate_bound_ = std::max(coordinate_bound_, q.center.cwiseAbs().sum());
        extent_bound_ = std::max(extent_bound_, q.half_extents.sum());
        nodes_.push_back(q);
        volumes_.push_back(node.volume);
        if (node.is_leaf()) {
            HBVH_ASSERT(node.primitive < primitive_nodes_.size());
            primitive_nodes_[node.primitive] = i;
        }
        // Nodes are breadth-first, so a parent's path sum is final before its children are reached.
        for (std::uint32_t c = node.first_child; c < node.first_child + node.child_count; ++c) {
            HBVH_ASSERT(c > i && c < bvh.nodes.size());
            path_sum[c] = path_sum[i] + node.child_count;
        }
        stack_bound_ = std::max(stack_bound_, path_sum[i]);
    }
    if (nodes_.empty()) return;
    // Leaves in depth-first order (an explicit stack: trees may be as deep as they have primitives), each
    // subtree's range closed once its last leaf is placed: children have larger indices than their parent,
    // so a reverse sweep sums the ranges bottom-up.
    leaves_.reserve(bvh.primitives.size());
    std::vector<std::uint32_t> pending{0};
    while (!pending.empty()) {
        const std::uint32_t i = pending.back();
        pending.pop_back();
        QueryNode& q = nodes_[i];
        if (q.child_count == 0) {
            q.leaf_begin = static_cast<std::uint32_t>(leaves_.size());
            q.leaf_count = 1;
            leaves_.push_back(i);
            continue;
        }
        for (std::uint32_t c = q.first_child + q.child_count; c-- > q.first_child;) pending.push_back(c);
    }
    for (std::uint32_t i = static_cast<std::uint32_t>(nodes_.size()); i-- > 0;) {
        QueryNode& q = nodes_[i];
        if (q.child_count == 0) continue;
        const QueryNode& first = nodes_[q.first_child];
        q.leaf_begin = first.leaf_begin;
        q.leaf_count = 0;
        for (std::uint32_t c = q.first_child; c < q.first_child + q.child_count; ++c) q.leaf_count += nodes_[c].leaf_count;
    }
}

}  // namespace hbvh
