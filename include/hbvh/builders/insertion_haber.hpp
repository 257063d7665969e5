// SPDX-License-Identifier: MIT
// Incremental insertion with Haber et al.'s refinements (survey §2.1): richer rules, re-insertion, ill-formed groups.
#pragma once

#include <cstdint>
#include <span>

#include "hbvh/builders/context.hpp"
#include "hbvh/result.hpp"
#include "hbvh/tree/bvh.hpp"

namespace hbvh {

/// Knobs of build_insertion_haber. See docs/algorithms-heuristics.md.
struct InsertionHaberOptions {
    /// Rule 4: p may form a new group with up to this many children of a group g (2 or more).
    std::uint32_t max_rule4_children = 6;
    /// Rounds of global optimisation (Successive Re-Insertion, then Elimination of Ill-formed Groups);
    /// a round that does not lower the cost ends the optimisation early.
    std::uint32_t optimization_rounds = 1;
    /// Successive Re-Insertion prices at most this many leaves per round, worst placed first.
    std::uint32_t max_reinsertions_per_round = 256;
    /// Elimination of Ill-formed Groups tries at most this many groups per round, loosest first
    /// (each try refits exactly, so this bounds the optimisation's cost).
    std::uint32_t max_eliminations_per_round = 8;
    /// Ill-formed group: Eq. 1 tightness (volume / sum of children's volumes) above this ...
    double max_tightness = 3.0;
    /// ... or a child whose volume is at least this fraction of the group's volume.
    double dominant_child_fraction = 0.7;
    /// As InsertionOptions::max_refit_primitives: 0, no cap; else the two-level tree once the exact refits have
    /// fitted this many primitives in all (the insertion's and the optimisation's).
    std::uint64_t max_refit_primitives = 0;
};

/// Inserts the primitives in input order, searching the whole tree (branch and bound on the Eq. 2
/// increase) with rules 1-3 of Goldsmith and Salmon plus rule 4 (p and several children of g form a new
/// group), then improves the tree globally: Successive Re-Insertion removes badly placed leaves and
/// inserts them again; Elimination of Ill-formed Groups dissolves groups that fail the badness criteria
/// and re-inserts their children. Every global step is kept only if it lowers the cost. Depends on input
/// order (less than build_insertion). Deadline: checked between insertions (the two-level tree if it
/// passes there) and between optimisation rounds (the tree as optimised so far).
[[nodiscard]] Result<Bvh> build_insertion_haber(std::span<const Primitive> primitives, const BuildContext& context,
                                                const InsertionHaberOptions& options = {});

}  // namespace hbvh
