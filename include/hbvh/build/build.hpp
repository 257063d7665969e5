// SPDX-License-Identifier: MIT
// The one place that maps an algorithm name to its builder. The CLI, the benchmarks and the tests all
// go through build(), so a new algorithm reaches all three after one edit here (STYLE.md §3).
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string_view>

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
    automatic,  ///< "auto": optimal, bnb-exact or scale by input size (auto_choice).
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
    /// Wall-clock limit for the whole build in seconds; 0 = none. scale and bnb-exact (and auto) pass it to
    /// their solvers as budgets and return the best hierarchy found; BuildReport::budget_hit tells.
    double time_limit_seconds = 0.0;
    /// Called with the fraction done (0..1] as the build progresses (scale: per level), from the calling
    /// thread. Empty: no calls. The library never prints; the CLI draws the bar.
    std::function<void(double fraction)> progress;
};

/// Input sizes at which `auto` switches builder: optimal up to auto_optimal_max_primitives, bnb-exact up to
/// auto_exact_max_primitives, scale above. Chosen from measured times with every BV kind allowed
/// (docs/scale.md §5): optimal takes ~1 s at 10 primitives and doubles per primitive; bnb-exact's O(n^3)
/// Tightest candidates take seconds at 20 and minutes at 50, far from the ~2000 once hoped for.
inline constexpr std::uint32_t auto_optimal_max_primitives = 10;
inline constexpr std::uint32_t auto_exact_max_primitives = 24;

/// The builder `auto` uses for `primitive_count` primitives.
[[nodiscard]] Algorithm auto_choice(std::size_t primitive_count);

/// Ok when the primitives' world box has a finite volume; otherwise an Error (no file) saying the model
/// must be scaled down. build() checks this first: Eq. 2 is meaningless once volumes overflow to infinity.
[[nodiscard]] Status check_finite_extent(std::span<const Primitive> primitives);

/// Builds a hierarchy over `primitives` (non-empty, already validated geometry).
/// Returns an Error for an empty input.
[[nodiscard]] Result<Bvh> build(std::span<const Primitive> primitives, Algorithm algorithm,
                                const BuildOptions& options = {});

}  // namespace hbvh
