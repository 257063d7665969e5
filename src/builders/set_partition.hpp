// SPDX-License-Identifier: MIT
// The set-partition problem of the survey's §3 (Eqs. 4-6): choose merging candidates that cover every
// node of a level exactly once at minimum total cost.
#pragma once

#include "hbvh/builders/budget.hpp"

#include <cstdint>
#include <optional>
#include <vector>

namespace hbvh {

/// One merging candidate: the level's node indices it merges (ascending, distinct) and its cost.
struct Candidate {
    std::vector<std::uint32_t> members;
    double cost = 0.0;
};

/// Limits for a solver; 0 means unlimited.

/// A solver's answer: indices into the candidate list, ascending.
struct Partition {
    std::vector<std::uint32_t> chosen;
    double cost = 0.0;
    std::uint64_t nodes_explored = 0;
    bool budget_hit = false;  ///< Stopped early; `chosen` is the best found, optimality not proven.
    double lower_bound = 0.0; ///< Proven lower bound on the optimum (== cost when proven optimal).
};

}  // namespace hbvh

#include <span>

namespace hbvh {

/// The survey's branch and bound (§3, Appendix A, Algorithms 2-3): a binary selector over candidates in
/// list order, a stack of chosen candidates, bound = cost so far + 2 x sum of volumes of uncovered nodes
/// (Eq. 7), with a growable bitset instead of the survey's 32-bit word. `node_volumes[j]` is the volume of
/// node j's BV. Kept as the reference solver. nullopt when no exact cover exists.
[[nodiscard]] std::optional<Partition> solve_reference_branch_and_bound(std::uint32_t node_count,
                                                                        std::span<const Candidate> candidates,
                                                                        std::span<const double> node_volumes,
                                                                        const SolverBudget& budget = {});

/// hbvh's exact solver: branch on the uncovered node with the fewest candidates, admissible per-node
/// lower bound, greedy + local-search initial solution. Same optimum as exhaustive search.
/// nullopt when no exact cover exists.
[[nodiscard]] std::optional<Partition> solve_exact(std::uint32_t node_count, std::span<const Candidate> candidates,
                                                   const SolverBudget& budget = {});

}  // namespace hbvh
