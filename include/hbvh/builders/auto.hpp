// SPDX-License-Identifier: MIT
// auto: the default builder — optimal for the smallest inputs, the cheapest of a size-dependent portfolio of
// the other builders above, then treelet refinement (docs/treelets.md).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "hbvh/builders/context.hpp"
#include "hbvh/builders/registry.hpp"
#include "hbvh/builders/treelet.hpp"
#include "hbvh/result.hpp"
#include "hbvh/tree/bvh.hpp"

namespace hbvh {

/// Input sizes at which `auto` changes strategy (auto_portfolio). Up to auto_optimal_max_primitives: the
/// optimal subset DP alone (~0.2 s at 10-12 primitives, doubling per primitive). Up to
/// auto_merge_max_primitives: the cheapest of insertion-haber, insertion, split, merge, scale and binned (none
/// wins everywhere, docs/results.md §1; bnb-exact was a member too, at 60-80 % of auto's time there, and never
/// strictly cheaper on the bundled and ../shared/data models: docs/treelets.md §4). Up to
/// auto_refine_each_max_primitives: the cheapest of scale, insertion-haber, insertion, split and binned; up to
/// auto_insertion_max_primitives: of insertion-haber, split and binned (scale and insertion never won there,
/// docs/treelets.md §4); up to
/// auto_portfolio_max_primitives: of binned and split (at 1000 primitives the insertions took 5-7 s, split
/// 0.2 s, binned 0.3 s, and either may be the cheaper). Above: binned alone, 0.2 s and 0.2 % cheaper than split
/// at 20 000 primitives, where split takes 3 s (docs/scale.md §9).
/// Treelet refinement (docs/treelets.md), before the comparison: of every member's tree up to
/// auto_refine_each_max_primitives, of the auto_refine_cheapest_members cheapest unrefined trees up to
/// auto_refine_max_primitives (the cheapest unrefined tree alone lost up to 4.4 % to another member refined).
inline constexpr std::uint32_t auto_optimal_max_primitives = 10;
inline constexpr std::uint32_t auto_merge_max_primitives = 24;
inline constexpr std::uint32_t auto_insertion_max_primitives = 200;
inline constexpr std::uint32_t auto_portfolio_max_primitives = 2'000;
inline constexpr std::uint32_t auto_refine_each_max_primitives = 32;
inline constexpr std::uint32_t auto_refine_cheapest_members = 2;
inline constexpr std::uint32_t auto_refine_max_primitives = 200;

/// The cap auto puts on its insertion members' exact refits (InsertionOptions::max_refit_primitives), in
/// primitives fitted: auto_insertion_refit_factor n ceil(log2 n). Over the bundled and `../shared/data` models
/// and generated scenes of 11-200 primitives the refits fitted at most 24 n ceil(log2 n) (docs/treelets.md §4); a
/// rope of 200 capsules in order fitted 212 n ceil(log2 n), as a chain whose every ancestor is fitted again for
/// each new capsule. Past the cap the member's tree would be a chain that another member beats anyway.
inline constexpr std::uint64_t auto_insertion_refit_factor = 64;
[[nodiscard]] std::uint64_t auto_insertion_refit_budget(std::size_t primitive_count);

/// Knobs of build_auto.
struct AutoOptions {
    /// Refine the winner at any size, not only up to auto_refine_max_primitives (CLI --refine).
    bool refine_always = false;
    TreeletOptions treelets;  ///< For the refinements (their time limit: what the members left).
};

/// The builders `auto` tries for `primitive_count` primitives, in tie-break order (the first wins ties).
[[nodiscard]] std::vector<Algorithm> auto_portfolio(std::size_t primitive_count);
/// The first member of auto_portfolio(primitive_count).
[[nodiscard]] Algorithm auto_choice(std::size_t primitive_count);

/// Every member of auto_portfolio(n) builds a tree (through the registry, with its default options), in
/// parallel, and the cheapest under Eq. 2 wins (first in the list on ties, whatever finished first). Up to
/// 2 000 primitives the winner then goes through the exact collapse: every inner node whose
/// dissolution into its parent lowers Eq. 2 is dissolved (the best of every subset, docs/treelets.md §4).
/// Deadline: the members share it — each gets what is left, and those that would start after it are
/// skipped (the first always runs) — and refinement gets what remains, stopping between treelets.
[[nodiscard]] Result<Bvh> build_auto(std::span<const Primitive> primitives, const BuildContext& context,
                                     const AutoOptions& options = {});

}  // namespace hbvh
