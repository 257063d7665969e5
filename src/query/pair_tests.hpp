// SPDX-License-Identifier: MIT
// Internal: the node-pair tests both queries share (sphere and box stand-ins, exact leaf tests on b's
// leaves moved once per query), the per-query checks and the traversal stack.
#pragma once

#include <array>
#include <bit>
#include <cstdint>
#include <memory>
#include <vector>

#include "hbvh/assert.hpp"
#include "hbvh/geometry/overlap.hpp"
#include "hbvh/query/tandem_traversal.hpp"

namespace hbvh::detail {

/// The enclosing-sphere test of two nodes whose centres are in one frame: false when the spheres are
/// apart, so the BVs are too. Either frame will do: the radii's padding covers the rounding of moving a
/// centre (geometry/overlap.cpp's slacks are smaller still).
inline bool spheres_meet(const QueryNode& x, const Vec3& other_center, double other_radius) {
    const double r = x.sphere_radius + other_radius;
    return (x.center - other_center).squaredNorm() <= r * r;
}

/// One node of a tree placed in the other tree's model frame: its stand-ins' centre at once (9
/// multiply-adds, all the sphere test needs), the box axes (27 more, unless they are the identity) only
/// when a box test asks for them, and then once for all the nodes it meets.
class Placed {
public:
    Placed(const QueryNode& node, const RigidTransform& t) : node_(&node), motion_(&t) {
        center_.noalias() = t.rotation * node.center + t.translation;
    }
    [[nodiscard]] const Vec3& center() const { return center_; }
    const Mat3& axes() {
        if (!has_axes_) {
            if (node_->axis_aligned)
                axes_ = motion_->rotation;
            else
                axes_.noalias() = motion_->rotation * node_->rotation;
            has_axes_ = true;
        }
        return axes_;
    }

private:
    const QueryNode* node_;
    const RigidTransform* motion_;
    Vec3 center_;
    Mat3 axes_;
    bool has_axes_ = false;
};

/// The six-face-axis separating-axis test (boxes_may_overlap's) of the enclosing boxes of `fixed` and of
/// `other`, placed in fixed's model frame, with the caller's `slack`. The rows of R = fixed^T * other are
/// formed one at a time, so that a separation on one of fixed's axes skips the rest of the product.
template <bool fixed_axis_aligned>
inline bool face_axes_overlap(const QueryNode& fixed, const QueryNode& other, Placed& placed, double slack) {
    const Vec3 offset = placed.center() - fixed.center;
    const Mat3& axes = placed.axes();
    Mat3 r;
    Vec3 t;
    for (int i = 0; i < 3; ++i) {
        if constexpr (fixed_axis_aligned) {
            r.row(i) = axes.row(i);
            t[i] = offset[i];
        } else {
            r.row(i).noalias() = fixed.rotation.col(i).transpose() * axes;
            t[i] = fixed.rotation.col(i).dot(offset);
        }
        if (std::abs(t[i]) > fixed.half_extents[i] + other.half_extents.dot(r.row(i).cwiseAbs().transpose()) + slack)
            return false;
    }
    for (int j = 0; j < 3; ++j)
        if (std::abs(t.dot(r.col(j))) > other.half_extents[j] + fixed.half_extents.dot(r.col(j).cwiseAbs()) + slack)
            return false;
    return true;
}

/// The enclosing-box test of `fixed` against `other`, placed in fixed's model frame: never false when the
/// two BVs overlap, given a query_slack(). Two spheres are already settled by the sphere test and pass.
inline bool boxes_meet(const QueryNode& fixed, const QueryNode& other, Placed& placed, double slack) {
    if (fixed.type == BvType::sphere && other.type == BvType::sphere) return true;
    return fixed.axis_aligned ? face_axes_overlap<true>(fixed, other, placed, slack)
                              : face_axes_overlap<false>(fixed, other, placed, slack);
}

/// The slack of every box test of one query between a and b (moved by t): boxes_may_overlap's 1e-12 of
/// (|centre offset|_1 + both boxes' half-extent sums + the coordinates the centres came from), with each
/// term replaced by its bound over the two trees, so that it is computed once per query instead of once
/// per test. A placed centre R c + t has |R c + t|_1 <= sqrt(3) |c|_1 + |t|_1, which the bound covers in
/// both directions of motion; a larger slack only makes the test more conservative.
inline double query_slack(const QueryTree& a, const QueryTree& b, const RigidTransform& t,
                          const RigidTransform& t_inverse) {
    constexpr double face_axis_slack = 1e-12;
    constexpr double placed_factor = 2.7320508075688772;  // 1 + sqrt(3)
    const double centres = placed_factor * (a.coordinate_bound() + b.coordinate_bound());
    const double motion = t.translation.cwiseAbs().sum() + t_inverse.translation.cwiseAbs().sum();
    return face_axis_slack * (2.0 * (centres + motion) + a.extent_bound() + b.extent_bound());
}

/// The roots' test of both queries: b's root moved by t against a's root, enclosing spheres then enclosing
/// boxes (boxes_meet with the query's slack).
inline bool roots_overlap(const QueryTree& a, const QueryTree& b, const RigidTransform& t, double slack) {
    const QueryNode& x = a.nodes()[0];
    const QueryNode& y = b.nodes()[0];
    Placed placed(y, t);
    return spheres_meet(x, placed.center(), y.sphere_radius) && boxes_meet(x, y, placed, slack);
}

/// b's leaves moved into a's frame, each at most once per query: their centres for the sphere test and
/// their exact BVs (moved with transformed(), so that leaf tests match a brute force written with it bit
/// for bit). Direct-mapped by node index into at most `max_slots` slots: a tree of up to that many nodes
/// never moves a leaf twice, a larger one only when two leaves of one query share a slot. One per thread,
/// grown to the largest tree queried (at most ~0.7 MB), so that queries allocate nothing once warm.
class MovedLeaves {
public:
    static constexpr std::uint32_t max_slots = 4096;

    /// Starts a query on tree b moved by t (kept by reference: both must outlive the query).
    void begin(const QueryTree& b, const RigidTransform& t) {
        tree_ = &b;
        motion_ = &t;
        const auto wanted = std::bit_ceil(static_cast<std::uint32_t>(std::min<std::size_t>(b.nodes().size(), max_slots)));
        if (slots_.size() < wanted) slots_.resize(wanted);
        mask_ = static_cast<std::uint32_t>(slots_.size()) - 1;
        if (++epoch_ == 0) {  // after 2^32 queries: forget every slot once rather than trust a stale stamp
            for (Slot& slot : slots_) slot.center_epoch = slot.volume_epoch = 0;
            epoch_ = 1;
        }
    }
    /// Leaf (or any node) i's centre in a's frame.
    const Vec3& center(std::uint32_t i) {
        Slot& slot = claim(i);
        if (slot.center_epoch != epoch_) {
            slot.center.noalias() = motion_->rotation * tree_->nodes()[i].center + motion_->translation;
            slot.center_epoch = epoch_;
        }
        return slot.center;
    }
    /// Leaf i's exact BV in a's frame.
    const BoundingVolume& volume(std::uint32_t i) {
        Slot& slot = claim(i);
        if (slot.volume_epoch != epoch_) {
            slot.volume = transformed(tree_->volume(i), *motion_);
            slot.volume_epoch = epoch_;
        }
        return slot.volume;
    }

private:
    struct Slot {
        std::uint32_t node = 0;
        std::uint32_t center_epoch = 0;
        std::uint32_t volume_epoch = 0;
        Vec3 center;
        BoundingVolume volume;
    };
    Slot& claim(std::uint32_t i) {
        Slot& slot = slots_[i & mask_];
        if (slot.node != i) {
            slot.node = i;
            slot.center_epoch = slot.volume_epoch = 0;
        }
        return slot;
    }

    std::vector<Slot> slots_;
    std::uint32_t mask_ = 0;
    std::uint32_t epoch_ = 0;
    const QueryTree* tree_ = nullptr;
    const RigidTransform* motion_ = nullptr;
};

/// This thread's MovedLeaves.
MovedLeaves& moved_leaves();

/// Exact test of a's leaf ia against b's leaf ib, whose centre in a's frame is center_b (from `moved`,
/// passed in so that loops over a's leaves read it once), sphere test first.
inline bool leaves_overlap(const QueryTree& a, std::uint32_t ia, const QueryTree& b, std::uint32_t ib,
                           const Vec3& center_b, MovedLeaves& moved) {
    return spheres_meet(a.nodes()[ia], center_b, b.nodes()[ib].sphere_radius) &&
           overlaps(a.volume(ia), moved.volume(ib));
}

/// Stack of node pairs with room for the worst case of both trees: uninitialised storage on the machine
/// stack when it fits (no per-query cost), the heap otherwise.
class PairStack {
public:
    /// A node pair; `next` > 0 resumes the expansion of an already visited pair at that child.
    struct Entry {
        std::uint32_t a, b, next;
    };
    explicit PairStack(std::size_t capacity) : capacity_(std::max(capacity, local_capacity)) {
        if (capacity > local_capacity) {
            heap_ = std::make_unique_for_overwrite<Entry[]>(capacity);
            data_ = heap_.get();
        }
    }
    void push(std::uint32_t ia, std::uint32_t ib, std::uint32_t next = 0) {
        HBVH_ASSERT(size_ < capacity_);
        data_[size_++] = {ia, ib, next};
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

/// Clears a result for a new query, keeping the pairs' capacity.
void reset(CollideResult& result);

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

/// Refuses a query whose poses are no rigid motions (sets result.error); true when it may go on.
bool poses_valid(const RigidTransform& pose_a, const RigidTransform& pose_b, CollideResult& result);

}  // namespace hbvh::detail
