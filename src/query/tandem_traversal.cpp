// SPDX-License-Identifier: MIT
// Tandem traversal (Erleben, Sporring, Henriksen & Dohlmann, Physics-Based Animation, 2005, ch. 12;
// Gottschalk 1996 for the idea of testing b's volumes in a's frame) and the two-level baseline.
#include "hbvh/query/tandem_traversal.hpp"

#include <algorithm>
#include <array>
#include <memory>
#include <optional>

#include "hbvh/assert.hpp"
#include "hbvh/geometry/overlap.hpp"
#include "hbvh/geometry/validation.hpp"
#include "hbvh/tree/validate.hpp"

namespace hbvh {
namespace {

// Enclosing spheres are padded so that rounding can never make the pre-test reject a pair the exact test
// would accept: rounding in the radius (relative to it), and in the centre, which a transform moves with an
// error of a few ulps of its coordinates (a radius-1 sphere at 1e5 lands ~2e-11 off). The pad, 1e-12 of
// radius + |centre|_1, dominates both and the exact tests' own slacks (<= 1e-13 of the coordinates,
// geometry/overlap.cpp).
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
    radius += sphere_padding * (radius + center.cwiseAbs().sum());
}

// The traversal reads one node per test: keep it compact (docs/queries.md, "Query layout").
static_assert(sizeof(QueryNode) == 152);

constexpr bool is_box(BvType type) { return type == BvType::aabb || type == BvType::obb; }

/// One of b's nodes, brought into a's frame lazily: the centre at once (9 multiply-adds, enough for the
/// sphere pre-test), the box axes or the full BV only when a pre-test passes, and then only once however
/// many of a's nodes it meets.
class MovedNode {
public:
    MovedNode(const QueryTree& tree, std::uint32_t index, const RigidTransform& t)
        : node_(&tree.nodes()[index]), tree_(&tree), index_(index), center_(t.apply(node_->center)) {}

    [[nodiscard]] const QueryNode& node() const { return *node_; }
    [[nodiscard]] const Vec3& center() const { return center_; }
    /// The box axes in a's frame.
    const Mat3& rotation(const RigidTransform& t) {
        if (!has_rotation_) {
            rotation_.noalias() = t.rotation * node_->rotation;
            has_rotation_ = true;
        }
        return rotation_;
    }
    /// The exact BV in a's frame, moved with the arithmetic of transformed() so that leaf tests match a
    /// brute force written with it bit for bit (an Aabb becomes an Obb).
    const BoundingVolume& volume(const RigidTransform& t) {
        if (!volume_) volume_.emplace(transformed(tree_->volume(index_), t));
        return *volume_;
    }

private:
    const QueryNode* node_;
    const QueryTree* tree_;
    std::uint32_t index_;
    bool has_rotation_ = false;
    Vec3 center_;
    Mat3 rotation_;
    std::optional<BoundingVolume> volume_;
};

/// The enclosing-sphere pre-test: false when the spheres are apart, so the BVs are too. Both centres in
/// one frame, whichever is cheaper (the padding covers the rounding of either choice).
inline bool spheres_meet(const QueryNode& x, const Vec3& other_center, double other_radius) {
    const double r = x.sphere_radius + other_radius;
    return (x.center - other_center).squaredNorm() <= r * r;
}

/// What boxes_may_overlap needs to know of the coordinates its centre was computed from: both nodes'
/// centres in their model frames and the motion's translation (L1 norms), whose rounding it must cover.
inline double coordinate_magnitude(const Vec3& center_a, const Vec3& center_b, const RigidTransform& t) {
    return center_a.cwiseAbs().sum() + center_b.cwiseAbs().sum() + t.translation.cwiseAbs().sum();
}

/// Overlap of a's node ia and b's moved node once the spheres met: two leaves get the exact primitive
/// test; inner pairs of boxes the six-face-axis test, which never rejects what the exact one accepts;
/// two spheres are settled by the pre-test; other inner pairs get the exact test.
inline bool refined_overlap(const QueryTree& a, std::uint32_t ia, MovedNode& nb, const RigidTransform& t) {
    const QueryNode& na = a.nodes()[ia];
    const QueryNode& b = nb.node();
    if (na.child_count != 0 || b.child_count != 0) {
        if (is_box(na.type) && is_box(b.type)) {
            const Vec3 d = nb.center() - na.center;
            const double coordinates = coordinate_magnitude(na.center, b.center, t) + nb.center().cwiseAbs().sum();
            if (na.type == BvType::aabb)  // identity axes: b's axes and centre are already in a's box frame
                return boxes_may_overlap(na.half_extents, b.half_extents, nb.rotation(t), d, coordinates);
            return boxes_may_overlap(na.half_extents, b.half_extents, na.rotation.transpose() * nb.rotation(t),
                                     na.rotation.transpose() * d, coordinates);
        }
        if (na.type == BvType::sphere && b.type == BvType::sphere) return true;
    }
    return overlaps(a.volume(ia), nb.volume(t));
}

/// Both tests in a's frame.
inline bool node_overlap(const QueryTree& a, std::uint32_t ia, MovedNode& nb, const RigidTransform& t) {
    return spheres_meet(a.nodes()[ia], nb.center(), nb.node().sphere_radius) && refined_overlap(a, ia, nb, t);
}

/// Stack of node pairs with room for the worst case of both trees: uninitialised storage on the machine
/// stack when it fits (no per-query cost), the heap otherwise.
class PairStack {
public:
    struct Entry {
        std::uint32_t a, b;
    };
    explicit PairStack(std::size_t capacity) : capacity_(std::max(capacity, local_capacity)) {
        if (capacity > local_capacity) {
            heap_ = std::make_unique_for_overwrite<Entry[]>(capacity);
            data_ = heap_.get();
        }
    }
    void push(std::uint32_t ia, std::uint32_t ib) {
        HBVH_ASSERT(size_ < capacity_);
        data_[size_++] = {ia, ib};
    }
    [[nodiscard]] bool empty() const { return size_ == 0; }
    Entry pop() { return data_[--size_]; }

private:
    static constexpr std::size_t local_capacity = 1024;
    std::array<Entry, local_capacity> local_;
    std::unique_ptr<Entry[]> heap_;
    Entry* data_ = local_.data();
    std::size_t capacity_;
    std::size_t size_ = 0;
};

void reset(CollideResult& result) {
    result.intersecting = false;
    result.error.reset();
    result.pairs.clear();
    result.bv_tests = result.primitive_tests = result.nodes_visited = 0;
}

/// Counts a test between two nodes as a primitive test (two leaves) or a BV test.
inline void count_test(const QueryNode& x, const QueryNode& y, CollideResult& result) {
    ++(x.child_count == 0 && y.child_count == 0 ? result.primitive_tests : result.bv_tests);
}

/// Counts a test as a primitive test (two leaves) or a BV test, and runs it.
inline bool counted_overlap(const QueryTree& a, std::uint32_t ia, MovedNode& nb, const RigidTransform& t,
                            CollideResult& result) {
    ++(a.nodes()[ia].child_count == 0 && nb.node().child_count == 0 ? result.primitive_tests : result.bv_tests);
    return node_overlap(a, ia, nb, t);
}

/// Refuses a query whose poses are no rigid motions; true when it may go on.
bool poses_valid(const RigidTransform& pose_a, const RigidTransform& pose_b, CollideResult& result) {
    for (const RigidTransform* pose : {&pose_a, &pose_b}) {
        if (Status valid = validate_pose(*pose); !valid) {
            result.error = Error{(pose == &pose_a ? "pose_a: " : "pose_b: ") + valid.error().message};
            return false;
        }
    }
    return true;
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
        q.center = Vec3::Zero();
        q.rotation = Mat3::Identity();
        q.half_extents = Vec3::Zero();
        q.measure = hbvh::volume(node.volume);
        q.first_child = node.first_child;
        q.child_count = node.child_count;
        q.primitive = node.primitive;
        q.type = type_of(node.volume);
        enclosing_sphere(node.volume, q.center, q.sphere_radius);
        if (const auto* box = std::get_if<Aabb>(&node.volume)) {
            q.half_extents = box->half_extents();
        } else if (const auto* obb = std::get_if<Obb>(&node.volume)) {
            q.rotation = obb->rotation;
            q.half_extents = obb->half_extents;
        }
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
}

RigidTransform relative_transform(const RigidTransform& pose_a, const RigidTransform& pose_b) {
    // R_a^T (T_b - T_a), not R_a^T T_b - R_a^T T_a: two objects kilometres from the origin but close to each
    // other then lose only the rounding of their small offset, not u x |T| of each (docs/reliability.md §5).
    const Mat3 inverse_rotation = pose_a.rotation.transpose();
    return {inverse_rotation * pose_b.rotation, inverse_rotation * (pose_b.translation - pose_a.translation)};
}

void collide(const QueryTree& a, const RigidTransform& pose_a, const QueryTree& b, const RigidTransform& pose_b,
             CollideMode mode, CollideResult& result) {
    reset(result);
    if (!poses_valid(pose_a, pose_b, result) || a.empty() || b.empty()) return;
    const RigidTransform t = relative_transform(pose_a, pose_b);
    const RigidTransform t_inverse = t.inverse();
    const std::span<const QueryNode> na = a.nodes(), nb = b.nodes();

    // Stage 1: the roots.
    {
        MovedNode root_b(b, 0, t);
        if (!counted_overlap(a, 0, root_b, t, result)) return;
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
            MovedNode moved_b(b, ib, t);  // moved once for all of a's children
            for (std::uint32_t c = node_a.first_child; c < node_a.first_child + node_a.child_count; ++c) {
                count_test(na[c], node_b, result);
                if (!spheres_meet(na[c], moved_b.center(), node_b.sphere_radius)) continue;
                if (!refined_overlap(a, c, moved_b, t)) continue;
                if (na[c].child_count == 0 && node_b.child_count == 0) {
                    report(c, ib);
                    if (mode == CollideMode::first) return;
                } else {
                    stack.push(c, ib);
                }
            }
        } else {
            // a's node stays put; its sphere centre goes into b's frame once, so that the pre-test of b's
            // children needs no transform, and only children that pass it are moved into a's frame.
            const Vec3 center_a = t_inverse.apply(node_a.center);
            // For box-box inner tests, b's model frame -> a's box frame in one go, so that each child of
            // b costs one 3x3 product instead of two.
            Mat3 to_box_a;
            Vec3 offset_a;
            if (is_box(node_a.type)) {
                to_box_a.noalias() = node_a.rotation.transpose() * t.rotation;
                offset_a.noalias() = node_a.rotation.transpose() * (t.translation - node_a.center);
            }
            for (std::uint32_t c = node_b.first_child; c < node_b.first_child + node_b.child_count; ++c) {
                const QueryNode& child = nb[c];
                count_test(node_a, child, result);
                if (!spheres_meet(child, center_a, node_a.sphere_radius)) continue;
                if (is_box(node_a.type) && is_box(child.type) && (node_a.child_count != 0 || child.child_count != 0)) {
                    const Mat3 axes = to_box_a * child.rotation;
                    const Vec3 center = to_box_a * child.center + offset_a;
                    const double coordinates = coordinate_magnitude(node_a.center, child.center, t);
                    if (!boxes_may_overlap(node_a.half_extents, child.half_extents, axes, center, coordinates))
                        continue;
                } else {
                    MovedNode moved_c(b, c, t);
                    if (!refined_overlap(a, ia, moved_c, t)) continue;
                }
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

namespace {
/// Both Bvhs as QueryTrees and `query` on them, or the result that carries their Error.
template <class Query>
CollideResult on_query_trees(const Bvh& a, const Bvh& b, Query query) {
    Result<QueryTree> tree_a = QueryTree::create(a);
    Result<QueryTree> tree_b = tree_a ? QueryTree::create(b) : Result<QueryTree>(tree_a.error());
    if (!tree_a || !tree_b) {
        CollideResult refused;
        refused.error = tree_a ? tree_b.error() : tree_a.error();
        return refused;
    }
    return query(*tree_a, *tree_b);
}
}  // namespace

CollideResult collide(const Bvh& a, const RigidTransform& pose_a, const Bvh& b, const RigidTransform& pose_b,
                      CollideMode mode) {
    return on_query_trees(a, b, [&](const QueryTree& ta, const QueryTree& tb) { return collide(ta, pose_a, tb, pose_b, mode); });
}

void collide_two_level(const QueryTree& a, const RigidTransform& pose_a, const QueryTree& b,
                       const RigidTransform& pose_b, CollideMode mode, CollideResult& result) {
    reset(result);
    if (!poses_valid(pose_a, pose_b, result) || a.empty() || b.empty()) return;
    const RigidTransform t = relative_transform(pose_a, pose_b);
    const std::span<const QueryNode> na = a.nodes(), nb = b.nodes();
    {
        MovedNode root_b(b, 0, t);
        if (!counted_overlap(a, 0, root_b, t, result)) return;
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
        MovedNode moved_b(b, leaf_b, t);
        for (const std::uint32_t leaf_a : a.primitive_nodes()) {
            ++result.primitive_tests;
            if (!node_overlap(a, leaf_a, moved_b, t)) continue;
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
    return on_query_trees(a, b, [&](const QueryTree& ta, const QueryTree& tb) {
        return collide_two_level(ta, pose_a, tb, pose_b, mode);
    });
}

}  // namespace hbvh
