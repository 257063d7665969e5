// SPDX-License-Identifier: MIT
// Internal: bnb-exact's candidate generator and solver, for its builder and its tests.
#pragma once

#include <cstdint>
#include <vector>

#include "bottom_up.hpp"

namespace hbvh {

/// The rich candidate generator: Tightest ∪ Enlarge ∪ k-nearest-neighbour sets. For each node i with
/// neighbours n_1, n_2, ... (nearest first, ties by index), the sets {i, n_1}, {i, n_1, n_2}, ... up to
/// enlarge_max_group_size(level size) members, and every pair {i, n_t}. A superset of what
/// tightest_candidates and enlarge_candidates offer.
[[nodiscard]] std::vector<std::vector<std::uint32_t>> rich_candidates(const Level& level,
                                                                      std::uint32_t nearest_neighbours = 6);

/// solve_exact as a LevelSolver (it needs no node volumes: its bound holds for any costs).
[[nodiscard]] LevelSolver exact_level_solver();

}  // namespace hbvh
