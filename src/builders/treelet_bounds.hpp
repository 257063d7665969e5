// SPDX-License-Identifier: MIT
// Internal: lower bounds of the fitted volumes a treelet's DP asks for, so that it fits only the sets its
// optimum can use (docs/treelets.md, "Fits on demand").
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "hbvh/fit/volume_policy.hpp"
#include "hbvh/geometry/primitive.hpp"
#include "hbvh/geometry/vector.hpp"

namespace hbvh::detail {

/// The least radius of the generating spheres of the primitives of `set` (indices into `primitives`).
[[nodiscard]] double least_radius(std::span<const Primitive> primitives, std::span<const std::uint32_t> set);

/// Points whose hull, grown by `margin` (at most least_radius of the set), every convex volume around the
/// primitives of `set` holds: the centres of their generating spheres, and for a sphere of radius r above the
/// margin the six points r - margin from its centre along the axes (each sphere is the ball of radius
/// r - margin around its centre grown by the margin).
[[nodiscard]] std::vector<Vec3> points_inside(std::span<const Primitive> primitives, std::span<const std::uint32_t> set,
                                              double margin);

/// What a bound is multiplied by: the least weight among the allowed kinds, times 8 under the Minkowski
/// measure (Brunn-Minkowski: vol(K - K) >= 8 vol(K), and K - K holds H - H for H inside K), less a millionth
/// for the rounding of the hull's and the fits' volumes.
[[nodiscard]] double bound_scale(const VolumePolicy& policy);

/// A lower bound of the weighted measure of every allowed volume around a set of primitives. Each such volume
/// is convex and holds H, the hull of the set's points_inside grown by the set's least radius (the margin), so
/// its volume is at least H's: by Steiner's formula V + S m + (1/2) sum of edge length x exterior angle m^2 +
/// 4/3 pi m^3 for a polytope of volume V and area S grown by m (each angle taken as the chord between its
/// faces' unit normals, which is below it).
struct SetBound {
    double bound = 0.0;
    double margin = 0.0;
    /// The hull's vertices (all the points where no hull was made: no solid, or more than the small-set hull
    /// takes; the bound is then the margin's ball): a union's hull is built from its parts'.
    std::vector<Vec3> points;
};

/// The bound of `set` from its own points.
[[nodiscard]] SetBound bound_set(std::span<const Primitive> primitives, std::span<const std::uint32_t> set,
                                 double scale);

/// The bound of the union of two disjoint sets from theirs: each part contributes its hull's vertices where its
/// margin is the union's, else its points recomputed for the union's margin. So each hull sees few points.
[[nodiscard]] SetBound bound_union(std::span<const Primitive> primitives, const SetBound& a,
                                   std::span<const std::uint32_t> set_a, const SetBound& b,
                                   std::span<const std::uint32_t> set_b, double scale);

}  // namespace hbvh::detail
