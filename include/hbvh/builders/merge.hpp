// SPDX-License-Identifier: MIT
// OpenTissue's bottom-up merge (Erleben et al. 2005; survey §2.3): collapse the cheapest edges of a neighbour graph.
#pragma once

#include <cstdint>
#include <span>

#include "hbvh/builders/context.hpp"
#include "hbvh/result.hpp"
#include "hbvh/tree/bvh.hpp"

namespace hbvh {

/// Knobs of build_merge. See docs/algorithms-heuristics.md.
struct MergeOptions {
    /// Merge postponement (survey §2.3): a collapse becomes a BVH group only once the graph-node covers at
    /// least this many BVH nodes, or fewer edges than this remain; otherwise the graph-node carries the
    /// union and is grouped in a later collapse. Groups get between `branching_factor` and
    /// `2 x branching_factor - 2` children (fewer only at the root). Values below 2 act as 2.
    /// Default 2, OpenTissue's own default degree: on our generated scenes and bundled models it gave the
    /// lowest Eq. 2 cost (geometric mean vs two-level 0.163 at 2, 0.188 at 3, 0.199 at 4, 0.238 at 8;
    /// docs/algorithms-heuristics.md): Eq. 2 charges every child with its parent's volume, and on these
    /// inputs the levels saved by wider groups did not pay for that. At 2 every collapse makes a group (plain binary agglomeration); raise it for the survey's
    /// "small and fat" trees.
    std::uint32_t branching_factor = 2;
    /// Graph edges join primitives whose BVs, scaled about their centres by this factor in every linear
    /// dimension, overlap (the survey's 25 %). Nodes left without an edge are scaled by it again, and again.
    double enlargement = 1.25;
    /// Price edges (Eq. 3) with fit_best around the covered primitives (true), or with the cheap pricing
    /// fitter: exact AABB and sphere, OBB and capsule in principal and hinted frames (false, default).
    /// fit_best costs about a millisecond per call here, and a build prices several edges per primitive;
    /// group BVs are always fit_best.
    bool exact_priorities = false;
};

/// Bottom-up hierarchy over a neighbour graph. Graph-nodes start as primitives; edges join enlarged-BV
/// overlaps; the edge with the smallest Eq. 3 priority (weighted volume of a BV fitted around both nodes'
/// covered primitives minus both nodes' volumes) is collapsed first. When the graph runs out of edges
/// with more than one graph-node left, the remaining graph-nodes are connected again by the same
/// enlargement rule. The cost does not depend on the order of `primitives`. Deadline: checked between
/// collapses.
[[nodiscard]] Result<Bvh> build_merge(std::span<const Primitive> primitives, const BuildContext& context,
                                      const MergeOptions& options = {});

}  // namespace hbvh
