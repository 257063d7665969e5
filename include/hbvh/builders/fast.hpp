// SPDX-License-Identifier: MIT
// fast: the speed preset for programs that build at run time (`--quality fast`) — binned's topology with its
// cheap fits, re-arranged by treelets priced with cheap fits on small objects, then fit_best on the few nodes
// that weigh most in Eq. 2.
#pragma once

#include <cstdint>
#include <span>

#include "hbvh/builders/context.hpp"
#include "hbvh/result.hpp"
#include "hbvh/tree/bvh.hpp"

namespace hbvh {

/// Knobs of build_fast. The defaults are the measured compromise (docs/fast.md).
struct FastOptions {
    /// Up to treelet_max_primitives primitives, the cheap tree is re-arranged by one bottom-up sweep of treelet
    /// refinement (docs/treelets.md) with this many units per treelet, every subset priced by fit_fast instead of
    /// fit_best: microseconds a fit, 0.1-0.9 ms in all for 12-42 primitives. Below 3 units nothing is done.
    std::uint32_t treelet_units = 5;
    /// Above this many primitives the sweep is skipped: its time grows faster than the rest of the preset's
    /// (1.8 ms at 54 primitives, 8 ms at 418: docs/fast.md), which is meant to stay near a millisecond.
    std::uint32_t treelet_max_primitives = 48;
    /// After the cheap build, this many inner nodes are refitted with fit_best over their primitives: those
    /// with the largest Eq. 2 terms (children x weighted volume), largest first. The root alone is most of
    /// the gain on compact objects; each fit costs about 0.1-0.3 ms on a few dozen primitives, and they run in
    /// parallel (docs/fast.md).
    std::uint32_t exact_fits = 2;
    /// Nodes over more primitives than this are not refitted (fit_best is O(n log n) with a large constant:
    /// seconds at 10^6 primitives), so the preset stays fast at any size.
    std::uint32_t exact_fit_max_primitives = 256;
    /// The root's cut is chosen by a look-ahead over this many candidate cuts (0: the greedy cut): each candidate's
    /// two sides are planned greedily and priced by their collapsed boxes (BinnedOptions::lookahead_candidates).
    /// Inputs of at most 64 primitives; a few microseconds per candidate (docs/fast.md).
    std::uint32_t lookahead_candidates = 6;
    /// Last, up to 2 000 primitives, the nodes whose removal lowers Eq. 2 are dissolved into their parents (the
    /// exact collapse over every subset of inner nodes, O(nodes x depth)): up to 3 % cheaper trees (docs/fast.md).
    bool collapse = true;
};

/// A hierarchy in about a millisecond for a few dozen primitives (O(n log n) beyond the refits):
/// 1. binned's binary tree (cuts between sorted centres priced by the sides' boxes, the root's chosen by a
///    look-ahead over `lookahead_candidates` cuts, each side planned greedily and priced by its boxes), its Eq. 2-optimal
///    collapse into nodes of up to 8 children, and its cheap fit of each kept node (exact AABB, the box in the
///    principal and DiTO frames, the capsule on the main axis, the sphere around the box centre);
/// 2. up to `treelet_max_primitives` primitives, one sweep of treelet refinement with `treelet_units` units whose
///    subsets are priced by fit_fast (the cheap fitter with the primitives' own frames as hints), each treelet
///    replaced only where that makes the tree cheaper;
/// 3. the `exact_fits` inner nodes with the largest children x weighted volume (among those over at most
///    `exact_fit_max_primitives` primitives) refitted with fit_best over their primitives, each kept only where
///    it is cheaper (so the tree is never costlier than step 1's). A refit depends on its set of primitives only,
///    so the root's starts on another core before step 1, and those of the cheap tree's heaviest nodes below the
///    root during step 2, each used where a final heaviest node has its set;
/// 4. with `collapse`, the exact collapse: the nodes whose removal lowers Eq. 2 dissolved into their parents.
/// Its trees cost more than `auto`'s (docs/fast.md has the table); use it where build time matters more.
/// Deterministic for any thread count (the refits are independent and run in parallel).
/// Deadline: binned's checks, then between treelets and before each refit (once passed, the rest is skipped; the
/// refits started early are used).
[[nodiscard]] Result<Bvh> build_fast(std::span<const Primitive> primitives, const BuildContext& context,
                                     const FastOptions& options = {});

}  // namespace hbvh
