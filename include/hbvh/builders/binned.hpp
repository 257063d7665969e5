// SPDX-License-Identifier: MIT
// binned: the large-scene builder — top-down binned splits on the volume heuristic, then the Eq. 2-optimal
// collapse of that binary tree into wide nodes (docs/scale.md §9).
#pragma once

#include <cstdint>
#include <span>

#include "hbvh/builders/context.hpp"
#include "hbvh/result.hpp"
#include "hbvh/tree/bvh.hpp"

namespace hbvh {

/// Knobs of build_binned. The defaults are the measured compromise (docs/scale.md §9).
struct BinnedOptions {
    /// Ranges of more than `sweep_max_primitives` primitives are cut between centroid bins: this many per
    /// axis, each cut priced as count(left) x volume(left) + count(right) x volume(right) of the sides' boxes.
    std::uint32_t bin_count = 32;
    /// Ranges of at most this many primitives try every cut of their centres sorted along x, y and z.
    std::uint32_t sweep_max_primitives = 16;
    /// In inputs of at most this many primitives, ranges of at most 64 are swept with each side priced by
    /// the pricing fitter around it (as split prices its small nodes) instead of by its box.
    std::uint32_t estimate_sweep_up_to = 2000;
    /// A look-ahead for the top cuts of small objects: ranges of at most 64 primitives shallower than
    /// `lookahead_depth` (0: none) are cut where the two sides, each planned greedily below, give the least
    /// collapsed box cost, among the greedy cut and the `lookahead_candidates` cheapest local minima of the
    /// sweep's price along each axis. Only where no estimate sweep is made (inputs above
    /// `estimate_sweep_up_to`). `fast` looks ahead at the root: the greedy first cut was most of its gap to
    /// `auto` on four models (docs/fast.md).
    std::uint32_t lookahead_depth = 0;
    std::uint32_t lookahead_candidates = 6;
    /// The most children a node of the result may have (2..16). The collapse keeps a binary node only where
    /// that lowers Eq. 2; this bounds how many it may merge into one.
    std::uint32_t max_children = 8;
    /// Where OBBs are allowed, every kept node tries the box in the principal frame of its sphere centres; those
    /// over at most `dito_fit_max_primitives` also the boxes in DiTO's frames of their spheres (extremal points
    /// along 13 directions, no hull); those between `hull_fit_min_primitives` and `hull_fit_max_primitives`
    /// fit_obb (hull-based) over their spheres, in inputs of at most `hull_fit_max_input` primitives (it costs
    /// about 0.6 µs a sphere, and at 10^6 primitives that band holds 2.5·10^7 spheres); every other node from
    /// `hull_fit_min_primitives` on fit_obb around its children's volumes (a few dozen points however large the
    /// node). Every node also has the exact AABB, the capsule on its main axis and the sphere around its box
    /// centre, where allowed.
    std::uint32_t dito_fit_max_primitives = 16;
    std::uint32_t hull_fit_min_primitives = 128;
    std::uint32_t hull_fit_max_primitives = 4096;
    std::uint32_t hull_fit_max_input = 200'000;
    /// Kept nodes over at most this many primitives also try fit_best (every fitter of fit/fit.hpp) over
    /// their primitives. 0: none (fit_best costs about 0.1 ms a call, the rest of a node's fit a microsecond).
    std::uint32_t exact_fit_max_primitives = 0;
    /// Inputs of at most this many primitives have every kept node refitted with fit_best as well.
    std::uint32_t exact_fit_all_up_to = 1000;
    /// Inputs of at most this many primitives also get split's tree (its default options), and the cheaper one
    /// (Eq. 2) is returned, so that binned is never costlier than split where split takes milliseconds: on small
    /// objects binned's box-priced cuts lost to split's by 0.3-1.3 % on two of 24 models (docs/scale.md §9).
    /// 0: binned's own tree always. `auto` turns it off for its binned member: its portfolio has split already.
    std::uint32_t guarantee_split_up_to = 64;
};

/// A hierarchy for large scenes (10^4 to 10^6 primitives and more), in O(n log n) and on every core:
/// 1. a binary tree, top-down: each range of primitives is cut where the two sides' boxes, weighted by their
///    primitive counts, have the least volume (between `bin_count` centroid bins per axis for large ranges,
///    between sorted centres for small ones; a range whose recursion grows deeper than 2 log2 n + 32 is cut at
///    its median instead, which bounds the depth);
/// 2. each binary node's volume: the cheapest allowed kind of its cheap fit over the generating spheres below;
/// 3. the collapse: the subset of binary nodes to keep that minimises Eq. 2 exactly, by dynamic programming
///    over the binary tree with at most `max_children` children per kept node;
/// 4. the kept nodes' volumes, refitted with fit_best where small;
/// 5. up to `guarantee_split_up_to` primitives, split's tree instead where that is cheaper.
/// Deterministic for any thread count (each range is cut by one task, from its contents only).
/// Deadline: checked at every range; progress: the share of primitives placed.
[[nodiscard]] Result<Bvh> build_binned(std::span<const Primitive> primitives, const BuildContext& context,
                                       const BinnedOptions& options = {});

}  // namespace hbvh
