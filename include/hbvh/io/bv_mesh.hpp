// SPDX-License-Identifier: MIT
// Triangle meshes of bounding volumes, the common ground of every picture hbvh draws (glTF, HTML viewer).
#pragma once

#include <cstdint>
#include <vector>

#include "hbvh/geometry/bounding_volume.hpp"

namespace hbvh {

/// An indexed triangle mesh in world space. Triangles are counter-clockwise seen from outside
/// (glTF's front-face rule), and normals are the exact outward surface normals at the vertices.
struct TriangleMesh {
    std::vector<Vec3> positions;          ///< World coordinates.
    std::vector<Vec3> normals;            ///< Unit length, one per position.
    std::vector<std::uint32_t> indices;   ///< Three per triangle, into positions.

    /// indices.size() / 3.
    [[nodiscard]] std::size_t triangle_count() const { return indices.size() / 3; }
};

/// How finely curved surfaces are tessellated. Boxes ignore it.
struct MeshDetail {
    std::uint32_t segments = 24;  ///< Vertices around each latitude ring; rounded up to a multiple of 4 (min 4).
    std::uint32_t rings = 12;     ///< Latitude bands from pole to pole; rounded up to an even number (min 2).
};

/// The surface of `bv` as triangles. Every vertex lies on the surface, and the mesh's bounding box is
/// exactly world_aabb(bv): the points where the BV touches its world AABB are always vertices.
///
/// Layouts (callers such as the HTML viewer rely on them):
/// - Aabb / Obb: 24 vertices, 4 per face in counter-clockwise order, faces -x, +x, -y, +y, -z, +z of the
///   box's own axes; triangles (4f, 4f+1, 4f+2) and (4f, 4f+2, 4f+3).
/// - Sphere: a UV sphere with poles on world z.
/// - Capsule: a UV sphere split at its equator along the capsule axis, the halves moved to p1 and p0
///   and joined by a cylinder (omitted when p0 == p1).
/// Degenerate volumes (zero radius, flat boxes) give degenerate triangles but still unit normals.
[[nodiscard]] TriangleMesh triangulate(const BoundingVolume& bv, const MeshDetail& detail = {});

}  // namespace hbvh
