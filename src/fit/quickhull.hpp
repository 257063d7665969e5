// SPDX-License-Identifier: MIT
// Internal: a triangulated 3-D convex hull of a small point set, without qhull's per-call set-up.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "hbvh/geometry/vector.hpp"

namespace hbvh::detail {

/// Inputs larger than this go to qhull: the hull below is quadratic in the worst case, and qhull's
/// set-up, which dominates small calls, is nothing beside a large one (docs/fitting.md, "Own hull").
inline constexpr std::size_t quickhull_max_points = 1024;

/// A closed triangulated convex surface: every triangle counter-clockwise seen from outside.
struct TriangleHull {
    std::vector<std::array<std::uint32_t, 3>> triangles;  ///< Indices into the input points.
    std::vector<std::array<std::uint32_t, 3>> neighbors;  ///< neighbors[t][k]: the triangle across t's edge k.
    std::vector<std::uint32_t> vertices;                  ///< The triangles' corners, ascending, each once.
};

/// Quickhull (Barber, Dobkin & Huhdanpaa 1996) in double arithmetic, triangles only (no facet merging).
/// A point counts as outside a face only when it is more than a tolerance (1e-12 of the points' largest
/// |x|+|y|+|z|) above the face's plane, so points on or within rounding of the surface are not vertices,
/// as in qhull. Returns nothing when the points span no solid (coincident, collinear or coplanar within
/// that tolerance) or when rounding made a step inconsistent (a visible region whose horizon is not one
/// loop, a sliver triangle, a surface that is not a closed triangulated sphere): the caller then asks qhull,
/// which merges facets to handle exactly those cases. Every returned hull has passed those checks.
/// `flat_within_rounding`, when given, tells the first kind of refusal apart: it is set when the points lie
/// within 1e-15 of that scale (a few units in the last place of the coordinates) of one plane, line or point,
/// where qhull cannot find a solid either and need not be asked.
[[nodiscard]] std::optional<TriangleHull> quickhull(std::span<const Vec3> points, bool* flat_within_rounding = nullptr);

}  // namespace hbvh::detail
