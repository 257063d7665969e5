// SPDX-License-Identifier: MIT
// Treelet refinement: a post-pass that re-arranges small subtrees of any hierarchy optimally under
// Eq. 2 and never increases the cost (docs/treelets.md).
#pragma once

#include <cstdint>

#include "hbvh/fit/volume_policy.hpp"
#include "hbvh/tree/bvh.hpp"

namespace hbvh {

/// Options of refine_treelets.
struct TreeletOptions {
    /// Units (subtrees kept whole) per treelet; each treelet fits up to 2^m - m - 1 subsets.
    /// Clamped to [2, optimal_hard_limit]. 7 is the measured sweet spot (docs/treelets.md §3).
    std::uint32_t max_units = 7;
    /// Bottom-up sweeps over all inner nodes; stops earlier after a sweep that changed nothing.
    std::uint32_t max_passes = 3;
    /// Wall-clock limit in seconds (0 = none); checked between treelets, the tree so far is returned.
    double time_limit_seconds = 0.0;
    /// Fit a set only once the DP's optimum, with lower bounds (hull volumes) standing in for the sets not
    /// fitted yet, uses it, and run a fit's capsule step only then too: the same optimum (docs/treelets.md, "Fits
    /// on demand", "The capsule on demand") with 2-10x fewer fits. false: fit every set of every treelet first,
    /// completely, as before 2026-12-06 (for comparisons and tests).
    bool bound_fits = true;
};

/// What refine_treelets did.
struct TreeletReport {
    std::uint32_t passes = 0;        ///< Sweeps run.
    std::uint32_t treelets = 0;      ///< Treelets solved.
    std::uint32_t replaced = 0;      ///< Treelets replaced by a strictly cheaper arrangement.
    std::uint64_t fits = 0;          ///< Fits made (distinct covered sets; repeats are cached).
    double cost_before = 0.0;        ///< Eq. 2 with the policy's weights.
    double cost_after = 0.0;
    bool time_limit_hit = false;
};

/// Treelet refinement of `bvh` (any valid hierarchy, e.g. from build()). For every inner node N, bottom-up,
/// the treelet is N's children expanded, largest weighted volume first, into at most
/// options.max_units units (subtrees kept whole); the cheapest tree over those units under Eq. 2, with
/// inner BVs fit_best over the covered primitives (or the existing BV where it is smaller), is found by
/// solve_optimal_hierarchy and replaces the treelet when strictly cheaper. So the result's cost under
/// `policy` is never above the input's, and it is exactly optimal when max_units >= the primitive count.
/// Deterministic for any TBB thread count. An empty or single-leaf input is returned unchanged, and so is any
/// input under a policy validate_policy refuses (one that allows no kind gave volumes around nothing).
[[nodiscard]] Bvh refine_treelets(const Bvh& bvh, const VolumePolicy& policy, const TreeletOptions& options = {},
                                  TreeletReport* report = nullptr);

}  // namespace hbvh
