// SPDX-License-Identifier: MIT
// Internal: the subset DP behind build_optimal, on an abstract volume function (also used by treelets).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "hbvh/builders/optimal.hpp"

namespace hbvh {

/// One inner node of an optimal hierarchy: the primitives it covers and its children's, as bit masks
/// over the input indices (bit i = primitive i). A child with one bit set is a leaf.
struct OptimalGroup {
    std::uint32_t covered = 0;
    std::vector<std::uint32_t> children;
};

/// The DP's answer: groups root first (parents before children), and the optimal Eq. 2 cost.
struct OptimalPlan {
    std::vector<OptimalGroup> groups;
    double cost = 0.0;
};

/// The DP core on an abstract volume function: `subset_volume[mask]` is the (weighted) volume of the BV
/// of the primitives in `mask`, for every mask of `count` bits (entries of masks with fewer than two bits
/// are ignored). Returns the tree minimising Eq. 2 — sum over inner nodes of children x volume — over
/// ALL rooted trees with `count` labelled leaves, any branching factor >= 2; leaves cost nothing.
/// Ties are broken deterministically. Preconditions: 1 <= count <= optimal_hard_limit,
/// subset_volume.size() == 2^count, volumes finite.
[[nodiscard]] OptimalPlan solve_optimal_hierarchy(std::uint32_t count, std::span<const double> subset_volume);

namespace detail {

/// The DP's tables (optimal_dp.cpp): for every subset S, best(S) (its cheapest subtree), P_k(S) (the cheapest
/// sum of best() over a partition of S into k blocks) and the k that best(S) chose.
struct SubsetTables {
    std::uint32_t count = 0;
    std::vector<double> best;
    std::vector<double> parts;  ///< P_k(S) at parts[S * count + k - 1], k = 1..|S|; infinite beyond |S|
    std::vector<std::uint8_t> children;

    [[nodiscard]] const double* row(std::uint32_t s) const { return parts.data() + std::size_t{s} * count; }
    [[nodiscard]] double* row(std::uint32_t s) { return parts.data() + std::size_t{s} * count; }
};

/// The tables for `subset_volume` (same preconditions as solve_optimal_hierarchy; count >= 2). From 12
/// primitives on, the subsets of one size are solved in parallel; the tables do not depend on the thread count.
[[nodiscard]] SubsetTables solve_subsets(std::uint32_t count, std::span<const double> subset_volume);

/// The tree the tables chose.
[[nodiscard]] OptimalPlan plan_of(const SubsetTables& tables);

/// The outside half of the DP: for every subset S of two or more primitives, the least cost of the rest of a
/// tree that has S as a node (all but S's own subtree, S's share of its parent's charge included), so that
/// tables.best[S] + result[S] is the cheapest tree through S under `subset_volume` (single-member entries are
/// infinite). O(n·3^n) like the DP; parallel, independent of the thread count.
[[nodiscard]] std::vector<double> cost_outside(const SubsetTables& tables, std::span<const double> subset_volume);

/// Every mask of `count` bits, grouped by its number of members (each group ascending).
[[nodiscard]] std::vector<std::vector<std::uint32_t>> masks_by_size(std::uint32_t count);

}  // namespace detail
}  // namespace hbvh
