// SPDX-License-Identifier: MIT
// Internal: the convex hull of the sphere centres and its covariance, the input of Gottschalk's OBB.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "../memory/thread_scratch.hpp"
#include "hbvh/geometry/sphere.hpp"

namespace hbvh::detail {

/// Faces beyond this many (the smallest ones) are not reported: they rarely orient the best box.
inline constexpr std::size_t max_face_normals = 48;

/// The hull's surface as triangles over the positions in HullSummary::vertices (slots), so that a projection's
/// outline can be read off it instead of sorted (outline_along). Made by our quickhull only: empty when qhull
/// made the hull, or the hull is degenerate.
struct HullSurface {
    std::vector<std::array<std::uint32_t, 3>> triangles;  ///< Slots, counter-clockwise seen from outside.
    std::vector<std::array<std::uint32_t, 3>> neighbors;  ///< neighbors[t][k]: the triangle across t's edge k.
    std::vector<Vec3> normals;                            ///< Unit, outward.
    [[nodiscard]] bool empty() const { return triangles.empty(); }
};

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
    /// The surface, when our quickhull made the hull.
    HullSurface surface;
};

/// Who computes the hull: `automatic` is our quickhull (quickhull.hpp) for sets of up to quickhull_max_points,
/// qhull for larger ones and for any set the quickhull declines; `qhull` is qhull alone, the reference the
/// tests and benchmarks hold the quickhull path to.
enum class HullMethod { automatic, qhull };

/// Convex hull of the centres of `spheres` (radii are ignored). Never prints, never throws.
/// Precondition: spheres non-empty.
[[nodiscard]] HullSummary summarize_hull(std::span<const Sphere> spheres, HullMethod method = HullMethod::automatic);

/// Scratch of outline_along, reused across calls so that loops over many directions allocate once.
struct OutlineScratch {
    std::vector<std::uint32_t> outline;    ///< The result: slots in order around the outline.
    std::vector<std::uint32_t> next_slot;  ///< Per slot, the next one along the outline.
    std::vector<unsigned char> facing;     ///< Per triangle, whether it faces the direction.
    std::vector<Eigen::Vector2d> projected;
};

/// Gives back whichever of the scratch's arrays one call grew large (memory/thread_scratch.hpp), so that a
/// per-thread OutlineScratch can be handed to ReleaseIfLarge like any array.
inline void release_if_large(OutlineScratch& scratch) {
    release_if_large(scratch.outline);
    release_if_large(scratch.next_slot);
    release_if_large(scratch.facing);
    release_if_large(scratch.projected);
}

/// The outline of `surface` seen along `direction`, into scratch.outline: the loop of edges between the
/// triangles that face `direction` and those that do not (faces within 1e-9 of parallel to it count as not
/// facing it), as slots in order around it. Its points project onto the polygon that bounds the hull's
/// projection (points on the polygon's edges included), so the 2-D hull of the projected vertices need not
/// be sorted out: O(triangles) and no sort. False when the surface is empty or when rounding made the loop
/// not simple (a face nearly parallel to `direction` classified against its neighbours): callers then
/// project every vertex and take hull_2d.
[[nodiscard]] bool outline_along(const HullSurface& surface, const Vec3& direction, OutlineScratch& scratch);

/// Covariance of the centres of `spheres[indices]` (all spheres when `indices` is empty), equally weighted.
[[nodiscard]] Mat3 point_covariance(std::span<const Sphere> spheres, std::span<const std::uint32_t> indices = {});

}  // namespace hbvh::detail
