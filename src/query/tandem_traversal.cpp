// SPDX-License-Identifier: MIT
// Tandem traversal (Erleben, Sporring, Henriksen & Dohlmann, Physics-Based Animation, 2005, ch. 12;
// Gottschalk 1996 for the idea of testing b's volumes in a's frame).
#include "hbvh/query/tandem_traversal.hpp"

#include <algorithm>

#include "hbvh/geometry/validation.hpp"
#include "pair_tests.hpp"
#include "sort_pairs.hpp"
#include "../simd/wide_clones.hpp"

namespace hbvh {
namespace {

using detail::MovedLeaves;
using detail::Placed;

/// Copies on top of each other, the survey's one regime where its Two-Level query beats a hierarchy (Table 4):
/// when the roots' enclosing spheres are nearly concentric (centres closer than this fraction of the smaller
/// radius), most leaf pairs meet, so the descent's inner tests buy nothing, and up to a limit the query tests
/// the leaf pairs directly, as the Two-Level query does. Mode first stops at the first contact, nearly always
/// among the first pairs tested, so its limit is higher. Measured on the peers' objects (docs/queries.md,
/// "Concentric roots"): it took every total-overlap row to at most 1.15x the Two-Level query in mode all, 5 more
/// rows under 1.2x in mode first with the higher limit, and changed no partial or near row beyond the noise.
/// Applied at deeper pairs too, it cost the 418-primitive humanoid scene 25 % in the partial and near regimes,
/// so it is the roots' rule only.
constexpr double concentric_fraction = 0.5;
constexpr std::uint64_t concentric_pair_limit_all = 1024;
constexpr std::uint64_t concentric_pair_limit_first = 4096;
static_assert(concentric_pair_limit_first <= QueryTree::contact_order_max_leaves);
/// Above the limit, mode first still tries this many leaf pairs of concentric roots before it descends: where
/// copies overlap, the first leaf of b nearly always meets one of a's first leaves (depth-first order keeps
/// neighbours together), and a probe that finds nothing costs a bounded few leaf tests (docs/queries.md,
/// "Concentric roots").
constexpr std::uint64_t concentric_probe_pairs = 64;

/// One query: the two trees, b's motion into a's frame and back, and where the answer goes.
class Traversal {
public:
    Traversal(const QueryTree& a, const QueryTree& b, const RigidTransform& t, CollideMode mode,
              std::uint64_t flat_limit, CollideResult& result, MovedLeaves& moved)
        : a_(a), b_(b), na_(a.nodes()), nb_(b.nodes()), t_(t), t_inverse_(t.inverse()),
          slack_(detail::query_slack(a, b, t, t_inverse_)), mode_(mode), flat_limit_(flat_limit), result_(result),
          moved_(moved) {}

    void run() {
        if (!roots_meet()) return;
        if (flat_limit_ != 0 && roots_concentric()) {
            const std::uint64_t pairs = std::uint64_t{na_[0].leaf_count} * nb_[0].leaf_count;
            const bool first = mode_ == CollideMode::first;
            if (pairs <= (first ? concentric_pair_limit_first : concentric_pair_limit_all)) {
                result_.nodes_visited = 1;
                // Mode first: most pairs of such roots meet and any one answers, so the cheapest are tried
                // first (each tree has at most concentric_pair_limit_first leaves, so it has its contact order).
                if (first)
                    all_pairs(a_.contact_order(), b_.contact_order());
                else
                    flat(na_[0], nb_[0]);
                return;
            }
            if (first && probe_roots(concentric_probe_pairs)) return;
        }
        // Depth-first over overlapping pairs. Every pair on the stack is known to overlap, and no pair of
        // leaves is ever pushed: those are reported when their test passes. In mode all the stack holds at
        // most the unexpanded siblings along one root-to-leaf path of each tree.
        // In mode first, any contact ends the query, so an expansion stops at the first child that meets the
        // other node and descends into it at once, leaving a resume entry for its siblings: two entries per
        // level (a stack bound is at least the depth), and about one test per level to the first contact
        // where the objects overlap deeply, instead of every child of every level.
        const bool depth_first = mode_ == CollideMode::first;
        const std::size_t bounds = std::size_t{a_.stack_bound()} + b_.stack_bound();
        detail::PairStack stack((depth_first ? 2 * bounds : bounds) + 1);
        stack.push(0, 0);
        while (!stack.empty()) {
            const auto [ia, ib, next] = stack.pop();
            const QueryNode& x = na_[ia];
            const QueryNode& y = nb_[ib];
            if (next == 0) {  // a new pair, not a resumed one
                ++result_.nodes_visited;
                if (std::uint64_t{x.leaf_count} * y.leaf_count <= flat_limit_) {
                    if (flat(x, y)) return;
                    continue;
                }
            }
            // Erleben et al.: descend the larger volume, so both trees shrink at about the same pace.
            if (y.child_count == 0 || (x.child_count != 0 && x.measure >= y.measure)) {
                Placed placed(y, t_);  // y moved once for all of x's children
                const std::uint32_t end = x.first_child + x.child_count;
                for (std::uint32_t c = next != 0 ? next : x.first_child; c < end; ++c) {
                    const QueryNode& child = na_[c];
                    if (child.child_count == 0 && y.child_count == 0) {
                        if (leaf_pair(c, ib, placed.center()) && found(c, ib)) return;
                        continue;
                    }
                    ++result_.bv_tests;
                    if (!detail::spheres_meet(child, placed.center(), y.sphere_radius) ||
                        !detail::boxes_meet(child, y, placed, slack_))
                        continue;
                    if (depth_first && c + 1 < end) stack.push(ia, ib, c + 1);
                    stack.push(c, ib);
                    if (depth_first) break;
                }
            } else {
                // x stays put: it is moved into b's frame once, so that each child of y is tested in its own
                // model frame with no motion of its own.
                Placed placed(x, t_inverse_);
                const std::uint32_t end = y.first_child + y.child_count;
                for (std::uint32_t c = next != 0 ? next : y.first_child; c < end; ++c) {
                    const QueryNode& child = nb_[c];
                    if (child.child_count == 0 && x.child_count == 0) {
                        if (leaf_pair(ia, c, moved_.center(c)) && found(ia, c)) return;
                        continue;
                    }
                    ++result_.bv_tests;
                    if (!detail::spheres_meet(child, placed.center(), x.sphere_radius) ||
                        !detail::boxes_meet(child, x, placed, slack_))
                        continue;
                    if (depth_first && c + 1 < end) stack.push(ia, ib, c + 1);
                    stack.push(ia, c);
                    if (depth_first) break;
                }
            }
        }
    }

private:
    /// The roots' test; a pair of lone leaves is answered by it.
    bool roots_meet() {
        const QueryNode& x = na_[0];
        const QueryNode& y = nb_[0];
        if (x.child_count == 0 && y.child_count == 0) {
            if (leaf_pair(0, 0, moved_.center(0))) {
                result_.nodes_visited = 1;
                found(0, 0);
            }
            return false;
        }
        ++result_.bv_tests;
        return detail::roots_overlap(a_, b_, t_, slack_);
    }

    /// The roots' enclosing spheres nearly share a centre.
    [[nodiscard]] bool roots_concentric() const {
        const QueryNode& x = na_[0];
        const QueryNode& y = nb_[0];
        const Vec3 placed = t_.rotation * y.center + t_.translation;
        const double reach = concentric_fraction * std::min(x.sphere_radius, y.sphere_radius);
        return (placed - x.center).squaredNorm() <= reach * reach;
    }

    /// Every leaf of x against every leaf of y; true when the query is answered (mode first).
    bool flat(const QueryNode& x, const QueryNode& y) {
        return all_pairs(a_.leaves().subspan(x.leaf_begin, x.leaf_count), b_.leaves().subspan(y.leaf_begin, y.leaf_count));
    }

    /// Every leaf of `leaves_a` against every leaf of `leaves_b`, b's outer; true when the query is answered.
    bool all_pairs(std::span<const std::uint32_t> leaves_a, std::span<const std::uint32_t> leaves_b) {
        for (const std::uint32_t leaf_b : leaves_b) {
            const Vec3 center_b = moved_.center(leaf_b);
            for (const std::uint32_t leaf_a : leaves_a)
                if (leaf_pair(leaf_a, leaf_b, center_b) && found(leaf_a, leaf_b)) return true;
        }
        return false;
    }

    /// The first `count` pairs of flat(root, root), in its order; true when one meets (mode first only). Its own
    /// loop: a budget counted in flat()'s would tax every flat pair of the descent (3-8 % on the partial rows).
    bool probe_roots(std::uint64_t count) {
        const std::span<const std::uint32_t> leaves_a = a_.leaves(), leaves_b = b_.leaves();
        for (const std::uint32_t leaf_b : leaves_b) {
            const Vec3 center_b = moved_.center(leaf_b);
            for (const std::uint32_t leaf_a : leaves_a) {
                if (count-- == 0) return false;
                if (leaf_pair(leaf_a, leaf_b, center_b) && found(leaf_a, leaf_b)) return true;
            }
        }
        return false;
    }

    /// The exact test of two leaves; center_b is b's leaf's centre in a's frame.
    bool leaf_pair(std::uint32_t ia, std::uint32_t ib, const Vec3& center_b) {
        ++result_.primitive_tests;
        return detail::leaves_overlap(a_, ia, b_, ib, center_b, moved_);
    }

    /// Reports a leaf pair; true when the query is answered (mode first).
    bool found(std::uint32_t ia, std::uint32_t ib) {
        result_.intersecting = true;
        result_.pairs.emplace_back(na_[ia].primitive, nb_[ib].primitive);
        return mode_ == CollideMode::first;
    }

    const QueryTree& a_;
    const QueryTree& b_;
    std::span<const QueryNode> na_, nb_;
    const RigidTransform& t_;
    const RigidTransform t_inverse_;
    const double slack_;  ///< Of every box test (detail::query_slack).
    CollideMode mode_;
    std::uint64_t flat_limit_;
    CollideResult& result_;
    MovedLeaves& moved_;
};

}  // namespace

RigidTransform relative_transform(const RigidTransform& pose_a, const RigidTransform& pose_b) {
    // A pose accepted within rotation_tolerance of a rotation is read as its nearest rotation: R_a^T is the inverse
    // below, and the traversal moves nodes both ways with R and R^T, so a rotation off by 4e-10 placed geometry 1e6
    // from the origin 4e-4 apart from one path to the other, and trees of the same primitives gave different pairs.
    const Mat3 rotation_a = exact_rotation(pose_a.rotation);
    const Mat3 rotation_b = exact_rotation(pose_b.rotation);
    // R_a^T (T_b - T_a), not R_a^T T_b - R_a^T T_a: two objects kilometres from the origin but close to each
    // other then lose only the rounding of their small offset, not u x |T| of each (docs/reliability.md §5).
    const Mat3 inverse_rotation = rotation_a.transpose();
    return {inverse_rotation * rotation_b, inverse_rotation * (pose_b.translation - pose_a.translation)};
}

// Compiled for AVX2 too, with the traversal and the node tests inlined (simd/wide_clones.hpp): 10-20 % less time
// on small trees (docs/queries.md, "An AVX2 copy of the queries").
HBVH_WIDE_CLONES_INLINED void collide(const QueryTree& a, const RigidTransform& pose_a, const QueryTree& b,
                                      const RigidTransform& pose_b, CollideMode mode, CollideResult& result,
                                      std::uint64_t flat_pair_limit) {
    detail::reset(result);
    if (!detail::poses_valid(pose_a, pose_b, result) || a.empty() || b.empty()) return;
    const RigidTransform t = relative_transform(pose_a, pose_b);
    MovedLeaves& moved = detail::moved_leaves();
    moved.begin(b, t);
    Traversal(a, b, t, mode, flat_pair_limit, result, moved).run();
    detail::sort_pairs(result.pairs, static_cast<std::uint32_t>(a.primitive_nodes().size()),
                       static_cast<std::uint32_t>(b.primitive_nodes().size()));
}

CollideResult collide(const QueryTree& a, const RigidTransform& pose_a, const QueryTree& b,
                      const RigidTransform& pose_b, CollideMode mode) {
    CollideResult result;
    collide(a, pose_a, b, pose_b, mode, result);
    return result;
}

CollideResult collide(const Bvh& a, const RigidTransform& pose_a, const Bvh& b, const RigidTransform& pose_b,
                      CollideMode mode) {
    return detail::on_query_trees(a, b, [&](const QueryTree& ta, const QueryTree& tb) { return collide(ta, pose_a, tb, pose_b, mode); });
}

}  // namespace hbvh
