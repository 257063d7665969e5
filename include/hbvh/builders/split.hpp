// SPDX-License-Identifier: MIT
// Müller et al.'s top-down splitting (survey §2.2): sort by centres on each world axis, cut at the cheapest point.
#pragma once

#include <cstdint>
#include <span>

#include "hbvh/builders/context.hpp"
#include "hbvh/result.hpp"
#include "hbvh/tree/bvh.hpp"

namespace hbvh {

/// Knobs of build_split. See docs/algorithms-heuristics.md.
struct SplitOptions {
    /// Nodes with at most this many primitives price each side of each cut with the pricing fitter
    /// around that side alone (exact AABB and sphere, OBB and capsule in the side's own principal frame);
    /// larger nodes use running bounds in the node's covariance frame (exact AABB, OBB in that frame,
    /// grown sphere, capsule on its main axis), so a sweep stays linear. 0: always the running bounds.
    std::uint32_t per_side_pricing_limit = 64;
};

/// Binary hierarchy by recursive two-way cuts. At every node the primitives are sorted by the centre of
/// their world box along x, y and z, every cut point is priced as
/// `count(left) x volume(left) + count(right) x volume(right)` (weighted volumes), and the cheapest cut
/// wins; recursion stops at single primitives. Node BVs are fit_best over the covered primitives.
/// The cost of the result does not depend on the order of `primitives` (ties break on geometry).
/// Deadline: checked at every node; progress: the share of primitives placed.
[[nodiscard]] Result<Bvh> build_split(std::span<const Primitive> primitives, const BuildContext& context,
                                      const SplitOptions& options = {});

}  // namespace hbvh
