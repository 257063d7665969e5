// SPDX-License-Identifier: MIT
// Tandem traversal (Erleben, Sporring, Henriksen & Dohlmann, Physics-Based Animation, 2005, ch. 12;
// Gottschalk 1996 for the idea of testing b's volumes in a's frame) and the two-level baseline.
#include "hbvh/query/tandem_traversal.hpp"

#include <algorithm>
#include <array>

#include "hbvh/assert.hpp"
#include "hbvh/geometry/overlap.hpp"

namespace hbvh {
namespace {

// Enclosing spheres are padded so that rounding in their radius can never make the pre-test reject a
// pair the exact test would accept.
constexpr double sphere_padding = 1e-12;

/// Centre and radius of a sphere around the BV (not the smallest; cheap and tight enough to reject).
void enclosing_sphere(const BoundingVolume& bv, Vec3& center, double& radius) {
    switch (bv.index()) {
        case 0: {
            const Aabb& box = *std::get_if<Aabb>(&bv);
            center = box.center();
            radius = box.half_extents().norm();
            break;
        }
        case 1: {
            const Obb& box = *std::get_if<Obb>(&bv);
            center = box.center;
            radius = box.half_extents.norm();
            break;
        }
        case 2: {
            const Sphere& s = *std::get_if<Sphere>(&bv);
            center = s.center;
            radius = s.radius;
            break;
        }
        default: {
            const Capsule& c = *std::get_if<Capsule>(&bv);
            center = c.center();
            radius = 0.5 * c.length() + c.radius;
            break;
        }
    }
    radius *= 1.0 + sphere_padding;
}

/// The BV moved by `t`; the same arithmetic as transformed() so that leaf tests match a brute force
/// written with it bit for bit (an Aabb becomes an Obb).
inline BoundingVolume moved(const BoundingVolume& bv, const RigidTransform& t) {
    switch (bv.index()) {
        case 0: return Obb::from_aabb(*std::get_if<Aabb>(&bv)).transformed(t);
        case 1: return std::get_if<Obb>(&bv)->transformed(t);
        case 2: return std::get_if<Sphere>(&bv)->transformed(t);
        default: return std::get_if<Capsule>(&bv)->transformed(t);
    }
}

/// One of b's nodes, brought into a's frame lazily: the sphere centre at once (9 multiply-adds), the full
/// BV only when a sphere pre-test passes, and then only once however many of a's nodes it meets.
struct MovedNode {
    const QueryNode* node = nullptr;
    Vec3 sphere_center;
    BoundingVolume volume;
    bool has_volume = false;

    MovedNode(const QueryNode& n, const RigidTransform& t) : node(&n), sphere_center(t.apply(n.sphere_center)) {}
};

/// Exact overlap of a's node and b's moved node, after the enclosing-sphere pre-test.
inline bool node_overlap(const QueryNode& na, MovedNode& nb, const RigidTransform& t) {
    const double r = na.sphere_radius + nb.node->sphere_radius;
    if ((na.sphere_center - nb.sphere_center).squaredNorm() > r * r) return false;
    if (!nb.has_volume) {
        nb.volume = moved(nb.node->volume, t);
        nb.has_volume = true;
    }
    return overlaps(na.volume, nb.volume);
}

/// Stack of node pairs with room for the worst case of both trees, on the machine stack when it fits.
class PairStack {
public:
    explicit PairStack(std::size_t capacity) {
        if (capacity > local_.size()) heap_.resize(capacity);
        data_ = heap_.empty() ? local_.data() : heap_.data();
        capacity_ = heap_.empty() ? local_.size() : heap_.size();
    }
    void push(std::uint32_t ia, std::uint32_t ib) {
        HBVH_ASSERT(size_ < capacity_);
        data_[size_++] = {ia, ib};
    }
    [[nodiscard]] bool empty() const { return size_ == 0; }
    std::pair<std::uint32_t, std::uint32_t> pop() { return data_[--size_]; }

private:
    std::array<std::pair<std::uint32_t, std::uint32_t>, 256> local_;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> heap_;
    std::pair<std::uint32_t, std::uint32_t>* data_ = nullptr;
    std::size_t capacity_ = 0;
    std::size_t size_ = 0;
};

void reset(CollideResult& result) {
    result.intersecting = false;
    result.pairs.clear();
    result.bv_tests = result.primitive_tests = result.nodes_visited = 0;
}

/// Counts a test as a primitive test (two leaves) or a BV test, and runs it.
inline bool counted_overlap(const QueryNode& na, MovedNode& nb, const RigidTransform& t, CollideResult& result) {
    ++(na.child_count == 0 && nb.node->child_count == 0 ? result.primitive_tests : result.bv_tests);
    return node_overlap(na, nb, t);
}

}  // namespace

QueryTree::QueryTree(const Bvh& bvh) {
    nodes_.reserve(bvh.nodes.size());
    primitive_nodes_.assign(bvh.primitives.size(), 0);
    std::vector<std::uint32_t> path_sum(bvh.nodes.size(), 0);
    for (std::uint32_t i = 0; i < bvh.nodes.size(); ++i) {
        const Node& node = bvh.nodes[i];
        QueryNode q{node.volume, Vec3::Zero(), 0.0, volume(node.volume), node.first_child, node.child_count, node.primitive};
        enclosing_sphere(node.volume, q.sphere_center, q.sphere_radius);
        nodes_.push_back(std::move(q));
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
}

RigidTransform relative_transform(const RigidTransform& pose_a, const RigidTransform& pose_b) {
    return pose_a.inverse() * pose_b;
}

void collide(const QueryTree& a, const RigidTransform& pose_a, const QueryTree& b, const RigidTransform& pose_b,
             CollideMode mode, CollideResult& result) {
    reset(result);
    if (a.empty() || b.empty()) return;
    const RigidTransform t = relative_transform(pose_a, pose_b);
    const std::span<const QueryNode> na = a.nodes(), nb = b.nodes();

    // Stage 1: the roots.
    {
        MovedNode root_b(nb[0], t);
        if (!counted_overlap(na[0], root_b, t, result)) return;
    }
    if (na[0].child_count == 0 && nb[0].child_count == 0) {
        result.intersecting = true;
        result.nodes_visited = 1;
        result.pairs.emplace_back(na[0].primitive, nb[0].primitive);
        return;
    }

    // Stage 2: depth-first over overlapping pairs. Every pair on the stack is known to overlap, and no
    // pair of leaves is ever pushed: those are reported when their test passes.
    // The stack holds at most the unexpanded siblings along one root-to-leaf path of each tree.
    PairStack stack(std::size_t{a.stack_bound()} + b.stack_bound() + 1);
    stack.push(0, 0);
    const auto report = [&](std::uint32_t ia, std::uint32_t ib) {
        result.intersecting = true;
        result.pairs.emplace_back(na[ia].primitive, nb[ib].primitive);
    };
    while (!stack.empty()) {
        const auto [ia, ib] = stack.pop();
        ++result.nodes_visited;
        const QueryNode& node_a = na[ia];
        const QueryNode& node_b = nb[ib];
        // Erleben et al.: descend the larger volume, so both trees shrink at about the same pace.
        const bool descend_a = node_b.child_count == 0 || (node_a.child_count != 0 && node_a.measure >= node_b.measure);
        if (descend_a) {
            MovedNode moved_b(node_b, t);  // moved once for all of a's children
            for (std::uint32_t c = node_a.first_child; c < node_a.first_child + node_a.child_count; ++c) {
                if (!counted_overlap(na[c], moved_b, t, result)) continue;
                if (na[c].child_count == 0 && node_b.child_count == 0) {
                    report(c, ib);
                    if (mode == CollideMode::first) return;
                } else {
                    stack.push(c, ib);
                }
            }
        } else {
            for (std::uint32_t c = node_b.first_child; c < node_b.first_child + node_b.child_count; ++c) {
                MovedNode moved_c(nb[c], t);
                if (!counted_overlap(node_a, moved_c, t, result)) continue;
                if (node_a.child_count == 0 && nb[c].child_count == 0) {
                    report(ia, c);
                    if (mode == CollideMode::first) return;
                } else {
                    stack.push(ia, c);
                }
            }
        }
    }
    std::sort(result.pairs.begin(), result.pairs.end());
}

CollideResult collide(const QueryTree& a, const RigidTransform& pose_a, const QueryTree& b,
                      const RigidTransform& pose_b, CollideMode mode) {
    CollideResult result;
    collide(a, pose_a, b, pose_b, mode, result);
    return result;
}

CollideResult collide(const Bvh& a, const RigidTransform& pose_a, const Bvh& b, const RigidTransform& pose_b,
                      CollideMode mode) {
    return collide(QueryTree(a), pose_a, QueryTree(b), pose_b, mode);
}

void collide_two_level(const QueryTree& a, const RigidTransform& pose_a, const QueryTree& b,
                       const RigidTransform& pose_b, CollideMode mode, CollideResult& result) {
    reset(result);
    if (a.empty() || b.empty()) return;
    const RigidTransform t = relative_transform(pose_a, pose_b);
    const std::span<const QueryNode> na = a.nodes(), nb = b.nodes();
    {
        MovedNode root_b(nb[0], t);
        if (!counted_overlap(na[0], root_b, t, result)) return;
    }
    result.nodes_visited = 1;
    if (na[0].child_count == 0 && nb[0].child_count == 0) {  // two lone primitives: already tested
        result.intersecting = true;
        result.pairs.emplace_back(na[0].primitive, nb[0].primitive);
        return;
    }
    // Every primitive pair, each of b's primitives moved once. Primitive tests use the same pre-test
    // as tandem traversal so that the comparison measures the hierarchy, not the pair test.
    for (const std::uint32_t leaf_b : b.primitive_nodes()) {
        MovedNode moved_b(nb[leaf_b], t);
        for (const std::uint32_t leaf_a : a.primitive_nodes()) {
            ++result.primitive_tests;
            if (!node_overlap(na[leaf_a], moved_b, t)) continue;
            result.intersecting = true;
            result.pairs.emplace_back(na[leaf_a].primitive, nb[leaf_b].primitive);
            if (mode == CollideMode::first) return;
        }
    }
    std::sort(result.pairs.begin(), result.pairs.end());
}

CollideResult collide_two_level(const QueryTree& a, const RigidTransform& pose_a, const QueryTree& b,
                                const RigidTransform& pose_b, CollideMode mode) {
    CollideResult result;
    collide_two_level(a, pose_a, b, pose_b, mode, result);
    return result;
}

CollideResult collide_two_level(const Bvh& a, const RigidTransform& pose_a, const Bvh& b,
                                const RigidTransform& pose_b, CollideMode mode) {
    return collide_two_level(QueryTree(a), pose_a, QueryTree(b), pose_b, mode);
}

}  // namespace hbvh
