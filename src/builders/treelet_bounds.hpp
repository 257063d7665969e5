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

/// Lower bounds of the weighted measure of every allowed volume around the union of some units (bit i of a
/// mask: unit i). Each such volume is convex and holds H, the hull of the units' points_inside grown by the
/// margin, so its volume is at least H's (Steiner's formula: V + S m + (1/2) sum of edge length x exterior
/// angle m^2 + 4/3 pi m^3 for a polytope of volume V and area S grown by m), and its self-Minkowski measure
/// at least 8 times that (Brunn-Minkowski: vol(K - K) >= 8 vol(K), and K - K holds H - H); times the least
/// weight among the allowed kinds. A mask's hull is built from the hull vertices of the mask without its
/// lowest unit and of that unit, so each hull sees few points.
class TreeletBounds {
public:
    TreeletBounds(std::vector<std::vector<Vec3>> unit_points, double margin, const VolumePolicy& policy);
    /// The bound for the units in `mask` (any non-empty mask); the ball of the margin where their points span
    /// no solid.
    [[nodiscard]] double bound(std::uint32_t mask);

private:
    /// Replaces the mask's points by their hull's vertices and records its bound. Where no hull is made (no
    /// solid, or more points than the small-set hull takes) the points stay and the bound is the margin's ball.
    void hull_of(std::uint32_t mask);

    std::vector<std::vector<Vec3>> points_;
    std::vector<double> bound_;  ///< -1 until computed
    std::vector<Vec3> unit_normals_;  ///< hull_of's scratch
    double margin_ = 0.0;
    double scale_ = 1.0;
};

}  // namespace hbvh::detail
