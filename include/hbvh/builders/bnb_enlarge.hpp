// SPDX-License-Identifier: MIT
// The survey's B&B-Enlarge (§3): bottom-up levels whose merging candidates come from growing each node's BV
// by 5 % steps until it meets others, and a set partition per level by the survey's branch and bound.
#pragma once

#include <cstdint>
#include <span>

#include "hbvh/builders/budget.hpp"
#include "hbvh/builders/context.hpp"
#include "hbvh/result.hpp"
#include "hbvh/tree/bvh.hpp"

namespace hbvh {

/// Knobs of B&B-Enlarge's heuristic; the defaults are the survey's.
struct EnlargeOptions {
    double step = 0.05;                  ///< Growth per step as a fraction of the original size (survey: 5 %).
    std::uint32_t min_collisions = 1;    ///< Enlarge until this many other nodes collide (survey: 1).
    std::uint32_t max_colliders = 0;     ///< Keep only the first this many colliders (earliest step, then
                                         ///< nearest centre); 0 keeps all, as the survey does.
    std::uint32_t max_steps = 100000;    ///< Hard cap on the steps, for BVs that never span the level.
    /// Each node offers every subset of its colliders of up to floor(lg n) - 1 members; where every node meets every
    /// other (100 overlapping spheres: C(99, 5) = 7.5e7 subsets a node) that took 6 GB and no time limit stopped it.
    /// A node whose colliders would make more subsets than this keeps only its first colliders (earliest step, then
    /// nearest centre) that stay within it: those 100 spheres then build in 7 s and 45 MB. 0: no cap, as the survey.
    /// The 18 bundled and ../shared/data models build the same trees with the cap as without (2026-12-08).
    std::uint64_t max_subsets_per_node = std::uint64_t{1} << 10;
};

/// Knobs of build_bnb_enlarge.
struct BnbEnlargeOptions {
    /// Per solver call (one per level, one more per fallback). The default node limit keeps the survey's
    /// exponential search to roughly 0.1 s per call and, unlike a time limit, is deterministic.
    SolverBudget budget{1'000'000, 0.0};
    EnlargeOptions enlarge;  ///< The candidate heuristic.
};

/// B&B-Enlarge. Deadline: checked between levels.
[[nodiscard]] Result<Bvh> build_bnb_enlarge(std::span<const Primitive> primitives, const BuildContext& context,
                                            const BnbEnlargeOptions& options = {});

}  // namespace hbvh
