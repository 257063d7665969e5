// SPDX-License-Identifier: MIT
// The one place that maps an algorithm name to its builder. The CLI, the benchmarks and the tests all
// go through build(), so a new algorithm reaches all three after one edit here (STYLE.md §3).
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "hbvh/build/bnb_exact.hpp"
#include "hbvh/build/bottom_up_merge.hpp"
#include "hbvh/build/branch_and_bound.hpp"
#include "hbvh/build/incremental_insert.hpp"
#include "hbvh/build/incremental_insert_haber.hpp"
#include "hbvh/build/obb_tree.hpp"
#include "hbvh/build/optimal.hpp"
#include "hbvh/build/report.hpp"
#include "hbvh/build/scale.hpp"
#include "hbvh/build/top_down_split.hpp"
#include "hbvh/build/treelet.hpp"
#include "hbvh/fit/volume_policy.hpp"
#include "hbvh/result.hpp"
#include "hbvh/tree/bvh.hpp"

namespace hbvh {

enum class Algorithm {
    two_level,
    bnb_tightest,
    bnb_enlarge,
    optimal,
    bnb_exact,
    merge,
    insertion,
    insertion_haber,
    split,
    obb_tree,
    scale,
    automatic,  ///< "auto": optimal, or the cheapest of a portfolio then treelet refinement (auto_portfolio).
};

/// One row of the registry: CLI name and a one-line summary.
struct AlgorithmInfo {
    Algorithm algorithm;
    std::string_view name;
    std::string_view summary;
};

/// Every registered builder, in the order `hbvh algorithms` lists them.
[[nodiscard]] std::span<const AlgorithmInfo> algorithms();
[[nodiscard]] std::optional<Algorithm> parse_algorithm(std::string_view name);
[[nodiscard]] std::string_view to_string(Algorithm algorithm);

/// Options common to all builders. Algorithm-specific knobs live in each builder's own options struct.
struct BuildOptions {
    VolumePolicy policy;
    BuildReport* report = nullptr;  ///< Filled when non-null.
    BranchAndBoundOptions branch_and_bound;  ///< bnb-tightest, bnb-enlarge.
    OptimalOptions optimal;         ///< For Algorithm::optimal.
    ExactBottomUpOptions bnb_exact;  ///< For Algorithm::bnb_exact.
    MergeOptions merge;              ///< For Algorithm::merge.
    InsertionOptions insertion;      ///< For Algorithm::insertion.
    HaberInsertionOptions insertion_haber;  ///< For Algorithm::insertion_haber.
    SplitOptions split;              ///< For Algorithm::split.
    ObbTreeOptions obb_tree;         ///< For Algorithm::obb_tree.
    ScaleOptions scale;              ///< For Algorithm::scale (time limit and progress come from below).
    /// Run refine_treelets on the builder's tree (CLI --refine). `auto` refines up to
    /// auto_refine_max_primitives whatever this says, and at any size when it is true.
    bool refine = false;
    TreeletOptions treelets;         ///< For the refinement (time limit: what the build left, see below).
    /// Wall-clock limit for the whole build in seconds; 0 = none. scale and bnb-exact (and auto) pass it to
    /// their solvers as budgets and return the best hierarchy found; BuildReport::budget_hit tells.
    /// `auto` passes it to each portfolio member (the heuristic members take milliseconds); treelet
    /// refinement gets what is left and stops between treelets when it runs out.
    double time_limit_seconds = 0.0;
    /// Called with the fraction done (0..1] as the build progresses (scale: per level), from the calling
    /// thread. Empty: no calls. The library never prints; the CLI draws the bar.
    std::function<void(double fraction)> progress;
};

/// Input sizes at which `auto` changes strategy (auto_portfolio). Up to auto_optimal_max_primitives: the
/// optimal subset DP alone (~1 s at 10 primitives, doubling per primitive). Up to
/// auto_exact_max_primitives: the cheapest of bnb-exact, insertion-haber, insertion, split, merge and scale
/// (bnb-exact's O(n^3) Tightest candidates take seconds at 20 and minutes at 50; the others milliseconds;
/// none wins everywhere, docs/results.md §1). Up to auto_insertion_max_primitives: the cheapest of scale,
/// insertion-haber, insertion and split; up to auto_portfolio_max_primitives: of scale and split (at 1000
/// primitives the insertions took 5-7 s, split 0.2 s, scale 0.15 s; at 20 000 split 3.4 s and 1.6x cheaper
/// than scale, 1.3 s). Above: scale alone (docs/scale.md §5).
/// With a time limit the members share it and those that would start after it are skipped.
/// Treelet refinement (docs/treelets.md): of every member's tree before the comparison up to
/// auto_refine_each_max_primitives, of the winner only up to auto_refine_max_primitives.
inline constexpr std::uint32_t auto_optimal_max_primitives = 10;
inline constexpr std::uint32_t auto_exact_max_primitives = 24;
inline constexpr std::uint32_t auto_insertion_max_primitives = 200;
inline constexpr std::uint32_t auto_portfolio_max_primitives = 20'000;
inline constexpr std::uint32_t auto_refine_each_max_primitives = 32;
inline constexpr std::uint32_t auto_refine_max_primitives = 200;

/// The builders `auto` tries for `primitive_count` primitives, in tie-break order (the first wins ties).
[[nodiscard]] std::vector<Algorithm> auto_portfolio(std::size_t primitive_count);
/// The first member of auto_portfolio(primitive_count).
[[nodiscard]] Algorithm auto_choice(std::size_t primitive_count);

/// Ok when the primitives' world box has a finite volume; otherwise an Error (no file) saying the model
/// must be scaled down. build() checks this first: Eq. 2 is meaningless once volumes overflow to infinity.
[[nodiscard]] Status check_finite_extent(std::span<const Primitive> primitives);

/// Appends a one-line summary of a treelet refinement to report.notes (and sets budget_hit on a time-out).
void note_treelets(BuildReport& report, const TreeletReport& treelets);

/// Builds a hierarchy over `primitives`. Returns an Error for an empty input, for geometry that
/// validate_primitives() refuses (naming the primitive) and for a model check_finite_extent() refuses.
[[nodiscard]] Result<Bvh> build(std::span<const Primitive> primitives, Algorithm algorithm,
                                const BuildOptions& options = {});

}  // namespace hbvh
