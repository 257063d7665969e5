// SPDX-License-Identifier: MIT
// The registry: one table of {name, summary, function} (src/builders/build.cpp). The CLI, the benchmarks and the
// tests all go through it, so a new builder — one file pair named after its CLI name plus one row there — reaches
// all three at once (STYLE.md §3).
#pragma once

#include <compare>
#include <optional>
#include <span>
#include <string_view>

#include "hbvh/builders/context.hpp"
#include "hbvh/geometry/primitive.hpp"
#include "hbvh/result.hpp"
#include "hbvh/tree/bvh.hpp"

namespace hbvh {

struct AlgorithmInfo;

/// A registered builder, known by its CLI name. The table in src/builders/build.cpp is the one list of builders;
/// the constants below name the ones this release ships (Algorithm::automatic is "auto"), and parse_algorithm
/// finds any row by name, so a builder added with only its row is reachable without a constant. Every value
/// names a row: the constants are checked against the table by a test, and nothing else makes one.
class Algorithm {
public:
    /// The CLI name, e.g. "insertion-haber".
    [[nodiscard]] constexpr std::string_view name() const { return name_; }
    friend constexpr bool operator==(Algorithm a, Algorithm b) { return a.name_ == b.name_; }
    /// By name, so that an Algorithm can key a std::map.
    friend constexpr auto operator<=>(Algorithm a, Algorithm b) { return a.name_ <=> b.name_; }

    static const Algorithm two_level, bnb_tightest, bnb_enlarge, optimal, bnb_exact, merge, insertion,
        insertion_haber, split, obb_tree, scale, binned, fast, automatic;

private:
    friend struct AlgorithmInfo;
    constexpr explicit Algorithm(std::string_view name) : name_(name) {}
    std::string_view name_;
};

inline constexpr Algorithm Algorithm::two_level{"two-level"};
inline constexpr Algorithm Algorithm::bnb_tightest{"bnb-tightest"};
inline constexpr Algorithm Algorithm::bnb_enlarge{"bnb-enlarge"};
inline constexpr Algorithm Algorithm::optimal{"optimal"};
inline constexpr Algorithm Algorithm::bnb_exact{"bnb-exact"};
inline constexpr Algorithm Algorithm::merge{"merge"};
inline constexpr Algorithm Algorithm::insertion{"insertion"};
inline constexpr Algorithm Algorithm::insertion_haber{"insertion-haber"};
inline constexpr Algorithm Algorithm::split{"split"};
inline constexpr Algorithm Algorithm::obb_tree{"obbtree"};
inline constexpr Algorithm Algorithm::scale{"scale"};
inline constexpr Algorithm Algorithm::binned{"binned"};
inline constexpr Algorithm Algorithm::fast{"fast"};
inline constexpr Algorithm Algorithm::automatic{"auto"};

/// Every builder's shape with its default options: build_NAME(primitives, context, {}).
using BuildFunction = Result<Bvh> (*)(std::span<const Primitive> primitives, const BuildContext& context);

/// One row of the registry.
struct AlgorithmInfo {
    std::string_view name;     ///< The CLI name, e.g. "insertion-haber"; the files are named after it.
    std::string_view summary;  ///< One line for `hbvh algorithms`.
    BuildFunction build;
    /// This row's builder as an Algorithm (for build(), build_refined() and the rest of the API).
    [[nodiscard]] constexpr Algorithm algorithm() const { return Algorithm(name); }
};

/// Every registered builder, in the order `hbvh algorithms` lists them.
[[nodiscard]] std::span<const AlgorithmInfo> algorithms();
/// The row of `algorithm`.
[[nodiscard]] const AlgorithmInfo& algorithm_info(Algorithm algorithm);
/// The registered builder named `name` (its CLI name), or nothing when no row has that name.
[[nodiscard]] std::optional<Algorithm> parse_algorithm(std::string_view name);
/// algorithm.name().
[[nodiscard]] constexpr std::string_view to_string(Algorithm algorithm) { return algorithm.name(); }

}  // namespace hbvh
