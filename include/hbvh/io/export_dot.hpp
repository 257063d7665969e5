// SPDX-License-Identifier: MIT
// Graphviz export: the hierarchy as a tree, like the right-hand halves of the survey's appendix C.
#pragma once

#include <string>

#include "hbvh/tree/bvh.hpp"

namespace hbvh {

/// Choices for export_dot.
struct DotOptions {
    /// Draw every primitive on the bottom row and a grey copy of a high leaf on each level between its
    /// parent and the bottom, as appendix C does ("nodes transferred directly from the level below").
    /// When false each leaf sits right under its parent.
    bool carry_leaves = true;
};

/// A Graphviz `digraph` of the tree, root at the top, one rank per depth. Inner nodes are labelled
/// with their BV type, volume and child count; leaves with their primitive's index, name (if any),
/// type and volume. Nodes are filled with level_color(depth) lightened; carried copies are grey and
/// dashed. The graph label gives node count, height and the Eq. 2 cost. Names are escaped for DOT.
/// An empty hierarchy gives an empty graph.
[[nodiscard]] std::string export_dot(const Bvh& bvh, const DotOptions& options = {});

}  // namespace hbvh
