// SPDX-License-Identifier: MIT
// Internal: the Eq. 2-optimal collapse of a finished hierarchy, dissolving inner nodes into their parents.
#pragma once

#include <cstddef>

#include "hbvh/fit/volume_policy.hpp"
#include "hbvh/tree/bvh.hpp"

namespace hbvh::detail {

/// The tree of least Eq. 2 cost (under `policy`) among all trees made from `bvh` by dissolving any of its
/// non-root inner nodes into their parents (a dissolved node's children become its parent's), with no limit
/// on a node's children. Every kept node keeps its volume, which still encloses its primitives, so the result
/// is as valid as the input and never dearer; a tie keeps the node. O(nodes x depth).
///
/// Eq. 2 charges a node its volume once per child, so a node whose volume is close to its parent's costs more
/// than it saves: on 300 copies of one sphere every tree built level by level is dearer than the flat one.
/// Builders that refine locally (treelets of a few units) never see across their units' boundaries; this does.
[[nodiscard]] Bvh collapse_optimally(const Bvh& bvh, const VolumePolicy& policy);

/// The builders that end with collapse_optimally do so up to this many primitives: its table holds one entry per
/// node and ancestor, a few hundred MB at 10^6 primitives, where binned has collapsed its own tree anyway.
inline constexpr std::size_t collapse_max_primitives = 2000;

}  // namespace hbvh::detail
