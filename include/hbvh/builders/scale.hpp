// SPDX-License-Identifier: MIT
// scale: bottom-up levels for 10^3 to 10^6 primitives — local candidates, exact partition per spatial window.
#pragma once

#include <cstdint>
#include <span>

#include "hbvh/builders/budget.hpp"
#include "hbvh/builders/context.hpp"
#include "hbvh/result.hpp"
#include "hbvh/tree/bvh.hpp"

namespace hbvh {

/// Options of build_scale (docs/scale.md). The defaults are the measured compromise for 2 cores.
struct ScaleOptions {
    /// Nodes per spatial window (consecutive in Morton order). Each window is one set-partition instance.
    std::uint32_t window_size = 32;
    /// Neighbours per node (nearest centres inside its window) from which candidates are formed.
    std::uint32_t nearest_neighbours = 5;
    /// Largest candidate group (2..4).
    std::uint32_t max_group_size = 4;
    /// Groups covering at most this many primitives are priced and fitted with fit_best (every fitter of
    /// fit/fit.hpp); larger ones with the cheap fitter (exact AABB and sphere, OBBs in a few given frames,
    /// capsules on a few given axes), which encloses just as surely but is not the tightest of its kind.
    std::uint32_t exact_fit_max_primitives = 0;
    /// Inputs of at most this many primitives use fit_best for every group (it is affordable there, and
    /// the tree is then comparable with optimal and bnb-exact, which use fit_best throughout).
    std::uint32_t exact_fit_all_up_to = 64;
    /// On levels of at most this many nodes the chosen groups are refitted with fit_best as well: the top
    /// levels' few big BVs dominate Eq. 2, and there are only a few hundred of them.
    std::uint32_t exact_fit_level_nodes = 256;
    /// ... but only for inputs of at most this many primitives. Measured on generated scenes (docs/scale.md
    /// §4): at 2·10^4 the refits make the tree 4 % cheaper for 0.5 s; at 2·10^5 they cost 6 of 18 s (fit_best
    /// over nodes of 10^5 primitives runs qhull over all their points) and the tree came out 3 % dearer.
    std::uint32_t exact_fit_level_max_input = 50'000;
    /// Per window solve_exact budget. A node limit, unlike a time limit, keeps the result deterministic.
    SolverBudget window_budget{20'000, 0.0};
    /// Price a fit_best group without a capsule step that may still win, at a lower bound, and run that step
    /// only for the groups a window's cover chooses, solving the window again until they are all priced
    /// exactly (docs/scale.md §1, "The capsule on demand"): the same covers for less fitting. false: every
    /// price exact before the first solve (for comparisons and tests).
    bool capsule_on_demand = true;
};

/// The scale builder: level by level bottom-up. Each level is sorted along a Morton curve of the node
/// centres and cut into windows of ~window_size nodes (boundaries shifted by half a window on odd
/// levels); in each window, every node and subsets of 1..3 of its nearest neighbours form candidates
/// priced as |group| x weighted volume (Eq. 2's share), and solve_exact picks the cheapest exact cover
/// (consecutive pairs in Morton order are always offered, so a cover exists). Windows run in parallel with
/// TBB and write to their own slots, combined in window order: the hierarchy is the same for any thread
/// count (unless time_limit_seconds cuts the search). Every inner node has 2..max_group_size children and
/// its BV encloses the generating spheres of all covered primitives. Precondition: primitives non-empty.
/// The report gets one row per level; lower_bound stays 0 (no global bound is known). Deadline: anytime —
/// once passed, the remaining windows keep the solver's initial (greedy + local search) cover instead of
/// searching; the result then depends on timing and BuildReport::budget_hit is set. Progress: per level.
[[nodiscard]] Result<Bvh> build_scale(std::span<const Primitive> primitives, const BuildContext& context,
                                      const ScaleOptions& options = {});

}  // namespace hbvh
