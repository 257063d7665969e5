// SPDX-License-Identifier: MIT
// bnb-exact: the survey's bottom-up levels with richer candidates and the exact solver (docs/solver.md §3).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "hbvh/build/bottom_up.hpp"
#include "hbvh/build/branch_and_bound.hpp"
#include "hbvh/build/report.hpp"

namespace hbvh {

/// Options of bnb-exact.
struct ExactBottomUpOptions {
    /// Per solve_exact call (one per level, more on fallbacks). The default node limit is deterministic.
    SolverBudget budget{5'000'000, 0.0};
    /// Neighbours per node for the k-nearest-neighbour candidates (by world-AABB centre distance).
    std::uint32_t nearest_neighbours = 6;
    /// Also build bnb-enlarge with `enlarge_options` and return the cheaper tree (Eq. 2), so that the
    /// result is never worse than bnb-enlarge's. Costs one bnb-enlarge build.
    bool guarantee_enlarge = true;
    BranchAndBoundOptions enlarge_options;
};

/// The rich candidate generator: Tightest ∪ Enlarge ∪ k-nearest-neighbour sets. For each node i with
/// neighbours n_1, n_2, ... (nearest first, ties by index), the sets {i, n_1}, {i, n_1, n_2}, ... up to
/// enlarge_max_group_size(level size) members, and every pair {i, n_t}. A superset of what
/// tightest_candidates and enlarge_candidates offer.
[[nodiscard]] std::vector<std::vector<std::uint32_t>> rich_candidates(const Level& level,
                                                                      std::uint32_t nearest_neighbours = 6);

/// solve_exact as a LevelSolver (it needs no node volumes: its bound holds for any costs).
[[nodiscard]] LevelSolver exact_level_solver();

/// bnb-exact: bottom-up levels, rich candidates, solve_exact per level; with guarantee_enlarge, the
/// cheaper of that and bnb-enlarge. Precondition: primitives non-empty.
[[nodiscard]] Bvh build_bnb_exact(std::span<const Primitive> primitives, const VolumePolicy& policy,
                                  const ExactBottomUpOptions& options = {}, BuildReport* report = nullptr);

}  // namespace hbvh
