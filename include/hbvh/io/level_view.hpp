// SPDX-License-Identifier: MIT
// Levels of a hierarchy as the survey's Figures 14-15 show them: each level a complete cover of the object.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "hbvh/tree/bvh.hpp"

namespace hbvh {

/// What one picture of a level shows.
///
/// Level d holds every node at depth d, plus every leaf at a smaller depth ("carried" leaves). Without
/// the carried leaves a primitive that hangs high in an unbalanced tree would vanish from the deeper
/// pictures; with them every level covers all primitives, like the survey's figures, and the deepest
/// level is exactly the primitive set. The survey's appendix C draws such carried nodes grey, and so do
/// hbvh's exporters.
struct LevelView {
    std::uint32_t depth = 0;             ///< 0 for the root's level.
    std::vector<std::uint32_t> nodes;    ///< Indices of the nodes at exactly this depth, ascending.
    std::vector<std::uint32_t> carried;  ///< Leaves of smaller depth shown again here, ascending.
    std::uint32_t inner_count = 0;       ///< How many of `nodes` are inner nodes.
    double volume = 0.0;                 ///< Sum of volume() over `nodes` (carried leaves not counted).
    double cost = 0.0;                   ///< This level's share of Eq. 2: child_count x volume over its inner nodes.
};

/// One view per depth, root first; empty for an empty hierarchy. The costs add up to cost(bvh).
[[nodiscard]] std::vector<LevelView> level_views(const Bvh& bvh);

/// Linear RGB in [0, 1].
using Rgb = std::array<double, 3>;
/// The colour that every exporter gives level `depth` (a fixed cycle of 8 distinguishable hues).
[[nodiscard]] Rgb level_color(std::uint32_t depth);
/// The neutral grey of carried leaves.
[[nodiscard]] Rgb carried_color();
/// "#rrggbb" of an Rgb (components clamped to [0, 1]).
[[nodiscard]] std::string to_hex(const Rgb& color);

}  // namespace hbvh
