// SPDX-License-Identifier: MIT
// The survey's two builders, B&B-Tightest and B&B-Enlarge (§3): bottom_up.hpp's driver with the
// heuristics of candidates.hpp and, by default, the survey's reference branch and bound.
#pragma once

#include <span>

#include "hbvh/build/bottom_up.hpp"
#include "hbvh/build/candidates.hpp"
#include "hbvh/build/report.hpp"

namespace hbvh {

/// Options of bnb-tightest and bnb-enlarge.
struct BranchAndBoundOptions {
    /// Per solver call (one per level, one more per fallback). The default node limit keeps the survey's
    /// exponential search to roughly 0.1 s per call and, unlike a time limit, is deterministic.
    SolverBudget budget{1'000'000, 0.0};
    /// The set-partition solver; empty means solve_reference_branch_and_bound (the survey's).
    LevelSolver solver;
    /// B&B-Enlarge's heuristic.
    EnlargeOptions enlarge;
};

/// B&B-Tightest: bottom-up levels, Tightest candidates, set partition per level. Precondition: non-empty.
[[nodiscard]] Bvh build_bnb_tightest(std::span<const Primitive> primitives, const VolumePolicy& policy,
                                     const BranchAndBoundOptions& options = {}, BuildReport* report = nullptr);
/// B&B-Enlarge: bottom-up levels, Enlarge candidates, set partition per level. Precondition: non-empty.
[[nodiscard]] Bvh build_bnb_enlarge(std::span<const Primitive> primitives, const VolumePolicy& policy,
                                    const BranchAndBoundOptions& options = {}, BuildReport* report = nullptr);

}  // namespace hbvh
