// SPDX-License-Identifier: MIT
// The registry: one table of {algorithm, name, summary, function}. The CLI, the benchmarks and the tests all
// go through it, so a new builder — one file pair named after its CLI name plus one row here — reaches all
// three at once (STYLE.md §3).
#pragma once

#include <optional>
#include <span>
#include <string_view>

#include "hbvh/builders/context.hpp"
#include "hbvh/geometry/primitive.hpp"
#include "hbvh/result.hpp"
#include "hbvh/tree/bvh.hpp"

namespace hbvh {

/// The registered builders, in the order `hbvh algorithms` lists them.
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
    binned,
    fast,
    automatic,  ///< "auto"
};

/// Every builder's shape with its default options: build_NAME(primitives, context, {}).
using BuildFunction = Result<Bvh> (*)(std::span<const Primitive> primitives, const BuildContext& context);

/// One row of the registry.
struct AlgorithmInfo {
    Algorithm algorithm;
    std::string_view name;     ///< The CLI name, e.g. "insertion-haber"; the files are named after it.
    std::string_view summary;  ///< One line for `hbvh algorithms`.
    BuildFunction build;
};

/// Every registered builder, in the order `hbvh algorithms` lists them.
[[nodiscard]] std::span<const AlgorithmInfo> algorithms();
[[nodiscard]] const AlgorithmInfo& algorithm_info(Algorithm algorithm);
[[nodiscard]] std::optional<Algorithm> parse_algorithm(std::string_view name);
[[nodiscard]] std::string_view to_string(Algorithm algorithm);

}  // namespace hbvh
