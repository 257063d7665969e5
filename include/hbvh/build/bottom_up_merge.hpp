// SPDX-License-Identifier: MIT
// OpenTissue's bottom-up merge (Erleben et al. 2005; survey §2.3): collapse the cheapest edges of a neighbour graph.
#pragma once

#include <cstdint>
#include <span>

#include "hbvh/fit/volume_policy.hpp"
#include "hbvh/result.hpp"
#include "hbvh/tree/bvh.hpp"

namespace hbvh {

/// Knobs of build_bottom_up_merge. See docs/algorithms-heuristics.md.
struct MergeOptions {
    /// Merge postponement (survey §2.3): a collapse becomes a BVH group only once the graph-node covers at
    /// least this many BVH nodes, or fewer edges than this remain. Groups therefore get between
    /// `branching_factor` and `2 x branching_factor - 2` children (fewer only near the root).
    /// Default 4: Eq. 2 charges every child with the parent's volume, so wide nodes pay only when their
    /// volume is small, and 4 gives short trees (the survey's "small and fat") with a few children per
    /// overlap test, like the quad/oct trees collision engines favour. Values below 2 act as 2.
    std::uint32_t branching_factor = 4;
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
/// enlargement rule. The cost does not depend on the order of `primitives`. Error: empty input.
[[nodiscard]] Result<Bvh> build_bottom_up_merge(std::span<const Primitive> primitives, const VolumePolicy& policy,
                                                const MergeOptions& options = {});

}  // namespace hbvh
