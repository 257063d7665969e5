// SPDX-License-Identifier: MIT
// Optimal: the globally cheapest hierarchy under Eq. 2 for small primitive sets, by dynamic programming
// over subsets (docs/solver.md §2). What the survey's §3 calls "not practically possible" in general is
// exact and fast enough up to ~18 primitives.
#pragma once

#include <cstdint>
#include <span>

#include "hbvh/builders/context.hpp"
#include "hbvh/result.hpp"
#include "hbvh/tree/bvh.hpp"

namespace hbvh {

/// Largest primitive count the subset DP accepts at all (2^20 subsets: ~180 MB of tables, minutes).
inline constexpr std::uint32_t optimal_hard_limit = 20;

/// Options of build_optimal.
struct OptimalOptions {
    /// Refuse (return an Error) above this many primitives; clamped to optimal_hard_limit.
    /// 18 builds in about a second with AABB/sphere and in 10-15 s with every kind on generated objects
    /// (fitting dominates; docs/solver.md §2).
    std::uint32_t max_primitives = 18;
    /// Above max_primitives: true builds bnb-exact's tree instead (noted in the report, lower bound 0, so
    /// every registered builder works at any size, as the shared property suites expect); false returns
    /// an Error that names the limit.
    bool fall_back = true;
};

/// The optimal hierarchy over `primitives`: optimal over all trees whose inner-node BVs are
/// fit_best(covered primitives) under `policy` (fitting input as FitInput over the covered primitives in
/// input order, as build_two_level does). Where boxes or capsules are allowed, subsets are fitted on demand:
/// lower bounds stand in until the DP's cheapest trees pass through them, and the tree is the optimum over
/// every subset's fit all the same. Fits and DP run in parallel with TBB; the result does not depend on the
/// thread count. Error when there are no primitives, or more than
/// options.max_primitives with fall_back off (with it on: bnb-exact's tree, not proven optimal). `report`, when non-null, gets one level entry and the proven optimum as lower
/// bound. Deadline: checked while the subset volumes are fitted and before the DP (the two-level tree
/// once it passes).
[[nodiscard]] Result<Bvh> build_optimal(std::span<const Primitive> primitives, const BuildContext& context,
                                        const OptimalOptions& options = {});

}  // namespace hbvh
