// SPDX-License-Identifier: MIT
// bnb-exact: the survey's bottom-up levels with richer candidates and the exact solver (docs/solver.md §3).
#pragma once

#include <cstdint>
#include <span>

#include "hbvh/builders/bnb_enlarge.hpp"
#include "hbvh/builders/budget.hpp"
#include "hbvh/builders/context.hpp"
#include "hbvh/result.hpp"
#include "hbvh/tree/bvh.hpp"

namespace hbvh {

/// Knobs of build_bnb_exact.
struct BnbExactOptions {
    /// Per solve_exact call (one per level, more on fallbacks). The default node limit is deterministic.
    SolverBudget budget{5'000'000, 0.0};
    /// Neighbours per node for the k-nearest-neighbour candidates (by world-AABB centre distance).
    std::uint32_t nearest_neighbours = 6;
    /// Also build bnb-enlarge with `enlarge_options` and return the cheaper tree (Eq. 2), so that the
    /// result is never worse than bnb-enlarge's. Costs one bnb-enlarge build.
    bool guarantee_enlarge = true;
    BnbEnlargeOptions enlarge_options;
};

/// bnb-exact: bottom-up levels, rich candidates, solve_exact per level; with guarantee_enlarge, the
/// cheaper of that and bnb-enlarge. Deadline: anytime — the time left is shared among the solver calls
/// (about 2 log2 n of them, half for its own search and half for bnb-enlarge's), each returning the best
/// partition found by then, so every level completes. Without a deadline its time grows steeply with the input
/// (1.2 s at 40 generated primitives, 9.7 s at 80, minutes at 150; README, "Builders").
[[nodiscard]] Result<Bvh> build_bnb_exact(std::span<const Primitive> primitives, const BuildContext& context,
                                          const BnbExactOptions& options = {});

}  // namespace hbvh
