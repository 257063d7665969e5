// SPDX-License-Identifier: MIT
// Stats: the survey's quality measures (Eq. 1, Eq. 2) and the shape of a hierarchy.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "hbvh/fit/volume_policy.hpp"
#include "hbvh/tree/bvh.hpp"

namespace hbvh {

/// min / mean / max of a per-node quantity.
struct Summary {
    double min = 0.0;
    double mean = 0.0;
    double max = 0.0;
};

struct Stats {
    double cost = 0.0;               ///< Eq. 2: sum over inner nodes of child_count x (weighted) volume.
    /// The same sum with each node measured by self_minkowski_volume instead (the calibrated objective,
    /// docs/metrics.md), with the policy's weights.
    double calibrated_cost = 0.0;
    std::uint32_t height = 0;        ///< Edges on the longest root-to-leaf path (a lone leaf: 0).
    std::uint32_t nodes = 0;
    std::uint32_t inner_nodes = 0;
    std::uint32_t leaves = 0;
    Summary branching;               ///< Children per inner node.
    Summary tightness;               ///< Eq. 1 per inner node: volume / sum of children's volumes; +inf for a node
                                     ///< with volume over children without any, NaN when no inner node has a ratio.
    Summary leaf_depth;              ///< Depth of each leaf (balance).
    double overlap = 0.0;            ///< See docs/metrics.md: sibling AABB overlap relative to sibling volume.
    std::array<std::uint32_t, bv_type_count> types{};  ///< Node count per BV kind (all nodes).
};

/// Eq. 2 with the policy's per-kind weights and node measure (weights 1 and volume give the survey's cost).
[[nodiscard]] double cost(const Bvh& bvh, const VolumePolicy& policy = {});
[[nodiscard]] Stats compute_stats(const Bvh& bvh, const VolumePolicy& policy = {});
/// Each node's depth (the root's 0), from the breadth-first layout: a child is deeper than its parent by one.
[[nodiscard]] std::vector<std::uint32_t> node_depths(const Bvh& bvh);
/// Edges on the longest root-to-leaf path (Stats::height) alone, in one pass.
[[nodiscard]] std::uint32_t height(const Bvh& bvh);

}  // namespace hbvh
