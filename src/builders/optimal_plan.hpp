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

}  // namespace hbvh
