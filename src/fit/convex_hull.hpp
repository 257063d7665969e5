// SPDX-License-Identifier: MIT
// Internal: the convex hull of the sphere centres and its covariance, the input of Gottschalk's OBB.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "hbvh/geometry/sphere.hpp"

namespace hbvh::detail {

/// Faces beyond this many (the smallest ones) are not reported: they rarely orient the best box.
inline constexpr std::size_t max_face_normals = 48;

/// What the fitters need from the convex hull of a set of sphere centres.
struct HullSummary {
    /// Indices (into the input) of the hull's vertices. When the hull is degenerate (fewer than four
    /// points, or all coplanar or collinear) this lists every input sphere, so callers never lose one.
    std::vector<std::uint32_t> vertices;
    /// Covariance of the hull surface (Gottschalk 1996, area-weighted over triangles) or, when the hull
    /// is degenerate, of the raw centres. Symmetric positive semi-definite.
    Mat3 covariance = Mat3::Zero();
    /// Unit outward normals of the hull's faces, largest face first, near-duplicates (the triangles of one
    /// flat face) merged, at most max_face_normals. Empty when the hull is degenerate.
    std::vector<Vec3> face_normals;
    /// True when the hull is full-dimensional with positive surface area.
    bool is_solid = false;
};

/// Who computes the hull: `automatic` is our quickhull (quickhull.hpp) for sets of up to quickhull_max_points,
/// qhull for larger ones and for any set the quickhull declines; `qhull` is qhull alone, the reference the
/// tests and benchmarks hold the quickhull path to.
enum class HullMethod { automatic, qhull };

/// Convex hull of the centres of `spheres` (radii are ignored). Never prints, never throws.
/// Precondition: spheres non-empty.
[[nodiscard]] HullSummary summarize_hull(std::span<const Sphere> spheres, HullMethod method = HullMethod::automatic);

/// Covariance of the centres of `spheres[indices]` (all spheres when `indices` is empty), equally weighted.
[[nodiscard]] Mat3 point_covariance(std::span<const Sphere> spheres, std::span<const std::uint32_t> indices = {});

}  // namespace hbvh::detail
