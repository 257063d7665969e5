// SPDX-License-Identifier: MIT
// Internal: the summed pairwise intersection volume of a set of boxes, the sibling overlap of compute_stats.
#pragma once

#include <span>

#include "hbvh/geometry/aabb.hpp"

namespace hbvh::detail {

/// The volume of the intersection of two boxes (0 when they are apart or only touch).
[[nodiscard]] double intersection_volume(const Aabb& a, const Aabb& b);

/// The sum over all pairs i < j of intersection_volume(boxes[i], boxes[j]). Few boxes are compared pair by
/// pair; many are binned into a grid of about as many cells as boxes, each pair examined in the one cell that
/// holds the lower corner of their intersection, and the boxes that would span many cells compared with all
/// the others. So a node's children cost O(n log n + pairs that meet) instead of O(n^2): a two-level tree
/// over 10^6 primitives has them all under its root. The order of the additions differs from the pair by
/// pair loop's, so the sum may differ from it in the last bits.
[[nodiscard]] double pairwise_intersection_volume(std::span<const Aabb> boxes);

}  // namespace hbvh::detail
