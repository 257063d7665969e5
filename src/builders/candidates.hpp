// SPDX-License-Identifier: MIT
// The survey's two merging-candidate heuristics (§3): Tightest (Fig. 10) and Enlarge (Fig. 11).
#pragma once

#include "hbvh/builders/bnb_enlarge.hpp"

#include <cstdint>
#include <vector>

#include "bottom_up.hpp"

namespace hbvh {

/// B&B-Tightest's heuristic (§3, Fig. 10). From each node, repeatedly add the node whose joint BV (fitted
/// around all covered primitives) has the smallest Eq. 1 tightness, saving every set of size >= 2 on the
/// way, until the set holds the whole level. Ties go to the lower canonical node index. A growth that
/// reaches a set an earlier start already grew through stops there (the rest would repeat it), so every
/// set is returned once; at most n (n - 1) sets and O(n^3) group fits, memoised by `level`.
[[nodiscard]] std::vector<std::vector<std::uint32_t>> tightest_candidates(const Level& level);


/// B&B-Enlarge's heuristic (§3, Fig. 11). Node i's BV B is scaled about its centre by s_k = 1 + k step,
/// k = 0, 1, 2, ... (k = 0 is B itself) until it overlaps (exact test, geometry/overlap.hpp) at least
/// `min_collisions` other nodes' BVs, or until its world AABB covers the level's bounds (or `max_steps`).
/// Every subset of {i} u colliders that contains i and has 2..enlarge_max_group_size(n) members is a
/// candidate. A node that never collides contributes nothing (the driver's fallback then covers it).
[[nodiscard]] std::vector<std::vector<std::uint32_t>> enlarge_candidates(const Level& level,
                                                                         const EnlargeOptions& options = {});

/// The survey's limit on an Enlarge candidate's size: max(2, floor(lg n)) for n nodes on the level.
[[nodiscard]] std::uint32_t enlarge_max_group_size(std::uint32_t node_count);

/// `bv` scaled by `scale` (>= 0) about its centre (box centre, sphere centre, capsule segment midpoint):
/// extents, radius and the capsule's segment all grow by the same factor, so the kind is kept.
[[nodiscard]] BoundingVolume scaled_about_center(const BoundingVolume& bv, double scale);

}  // namespace hbvh
