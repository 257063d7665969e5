// SPDX-License-Identifier: MIT
// validate: the whole-tree invariants every builder must keep, and every stored hierarchy is checked against.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "hbvh/result.hpp"
#include "hbvh/tree/bvh.hpp"

namespace hbvh {

/// The relative tolerance validate() and the CLI use by default (see containment_tolerance).
inline constexpr double default_containment_tolerance = 1e-9;

/// The layout queries rely on, checked without reading out of bounds whatever the node array holds:
/// child ranges inside the array (computed in 64 bits, so first_child + child_count cannot wrap),
/// breadth-first order (the children of the inner nodes, taken in index order, tile nodes[1, n) exactly),
/// no inner node with fewer than 2 children, every primitive in exactly one leaf whose volume is that primitive's
/// (the same kind and numbers), and every volume (nodes and primitives) usable geometry (volume_problem()). The
/// Error names the first node that fails.
[[nodiscard]] Status check_structure(const Bvh& bvh);

/// How far a primitive may reach beyond a node's volume before validate() calls it not enclosed:
/// `relative_tolerance` of the volume's size (size_scale) plus 1e-14 of its coordinates' magnitude (the
/// rounding of a fit or of the check itself far from the origin, a few dozen ulps). Purely relative: a
/// model in millimetres is held to the same standard as one in kilometres.
[[nodiscard]] double containment_tolerance(const BoundingVolume& volume,
                                           double relative_tolerance = default_containment_tolerance);

/// An inner node whose volume misses part of a primitive below it.
struct ContainmentViolation {
    std::uint32_t node = 0;       ///< Index in Bvh::nodes.
    std::uint32_t primitive = 0;  ///< The covered primitive that reaches furthest out (input order).
    double protrusion = 0.0;      ///< How far it reaches beyond the node's volume (protrusion()).
};

/// Every node that does not enclose all the primitives below it (within containment_tolerance), each with
/// its worst primitive, in node order. Precondition: check_structure(bvh) passed. Every node is held against
/// every generating sphere below it, on every core: O(n x height), so n log n for a balanced tree and quadratic
/// for a chain (40 000 deep: about a second).
[[nodiscard]] std::vector<ContainmentViolation> containment_violations(
    const Bvh& bvh, double relative_tolerance = default_containment_tolerance);

/// A violation in words, as the CLI and the Python module report it: "volume (obb) does not enclose primitive 3
/// ('leg') by 0.0125" (the name when it has one, the protrusion to three significant digits).
[[nodiscard]] std::string describe_violation(const Bvh& bvh, const ContainmentViolation& violation);

/// check_structure(), then containment: every node's BV holds every covered primitive (relative
/// tolerance, see containment_tolerance). The Error names the first node that fails.
[[nodiscard]] Status validate(const Bvh& bvh, double relative_tolerance = default_containment_tolerance);

}  // namespace hbvh
