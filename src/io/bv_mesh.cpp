// SPDX-License-Identifier: MIT
// Tessellation of boxes, spheres and capsules into triangle meshes with exact normals.
#include "hbvh/io/bv_mesh.hpp"

#include <cmath>
#include <limits>
#include <numbers>

#include "hbvh/assert.hpp"

namespace hbvh {
namespace {

/// Appends one planar quad (corners counter-clockwise seen from outside) with normal `normal`.
void add_quad(TriangleMesh& mesh, const std::array<Vec3, 4>& corners, const Vec3& normal) {
    const auto base = static_cast<std::uint32_t>(mesh.positions.size());
    // The caller orders corners by the box axes; an improper rotation (a mirror) would turn the face
    // inside out, so the winding is checked against the normal rather than trusted.
    const bool reversed = (corners[1] - corners[0]).cross(corners[2] - corners[0]).dot(normal) < 0.0;
    for (int k = 0; k < 4; ++k) {
        mesh.positions.push_back(corners[reversed ? 3 - k : k]);
        mesh.normals.push_back(normal);
    }
    for (std::uint32_t offset : {0u, 1u, 2u, 0u, 2u, 3u}) mesh.indices.push_back(base + offset);
}

/// A box from its centre, axes (columns) and half extents. `corner(bits)` gives the exact corner so
/// that an Aabb's vertices are its min/max bit for bit.
template <class CornerFn>
TriangleMesh box_mesh(const Mat3& axes, CornerFn corner) {
    TriangleMesh mesh;
    mesh.positions.reserve(24);
    mesh.normals.reserve(24);
    mesh.indices.reserve(36);
    for (int axis = 0; axis < 3; ++axis) {
        // The other two axes in cyclic order, so that first x second = this axis.
        const int first = (axis + 1) % 3;
        const int second = (axis + 2) % 3;
        for (int side = 0; side < 2; ++side) {
            const int fixed = side << axis;
            const auto at = [&](int a, int b) { return corner(fixed | (a << first) | (b << second)); };
            std::array<Vec3, 4> corners{at(0, 0), at(1, 0), at(1, 1), at(0, 1)};
            Vec3 normal = axes.col(axis).normalized();
            if (side == 0) {
                normal = -normal;
                std::swap(corners[1], corners[3]);
            }
            add_quad(mesh, corners, normal);
        }
    }
    return mesh;
}

/// A sphere (p0 == p1) or capsule around the segment p0-p1 with radius r. The unit sphere is cut into
/// `rings` latitude bands measured from +w; the northern half is centred on p1, the southern on p0.
TriangleMesh swept_sphere_mesh(const Vec3& p0, const Vec3& p1, double radius, const Mat3& frame,
                               const MeshDetail& detail) {
    const std::uint32_t segments = std::max<std::uint32_t>(4, (detail.segments + 3) / 4 * 4);
    const std::uint32_t rings = std::max<std::uint32_t>(2, (detail.rings + 1) / 2 * 2);
    const bool has_cylinder = p0 != p1;
    const Vec3 u = frame.col(0), v = frame.col(1), w = frame.col(2);
    TriangleMesh mesh;
    const auto add_vertex = [&](const Vec3& centre, const Vec3& direction) {
        mesh.positions.push_back(centre + radius * direction);
        mesh.normals.push_back(direction);
    };

    // Stage 1: vertices. North pole, the rings (the equator twice for a capsule), south pole.
    add_vertex(p1, w);
    std::uint32_t row_count = 0;
    for (std::uint32_t ring = 1; ring < rings; ++ring) {
        const double theta = std::numbers::pi * ring / rings;
        const bool north = 2 * ring <= rings;
        const int copies = (2 * ring == rings && has_cylinder) ? 2 : 1;
        for (int copy = 0; copy < copies; ++copy) {
            const Vec3& centre = (north && copy == 0) ? p1 : p0;
            for (std::uint32_t s = 0; s < segments; ++s) {
                const double phi = 2.0 * std::numbers::pi * s / segments;
                // Exact zeros at the quarter turns keep the world-axis extremes exact for spheres.
                const double cos_phi = (4 * s == segments || 4 * s == 3 * segments) ? 0.0 : std::cos(phi);
                const double sin_phi = (2 * s == segments || s == 0) ? 0.0 : std::sin(phi);
                const double cos_theta = 2 * ring == rings ? 0.0 : std::cos(theta);
                add_vertex(centre, std::sin(theta) * (cos_phi * u + sin_phi * v) + cos_theta * w);
            }
            ++row_count;
        }
    }
    add_vertex(p0, -w);
    const auto south = static_cast<std::uint32_t>(mesh.positions.size() - 1);

    // Stage 2: triangles, counter-clockwise seen from outside (see the header's orientation rule).
    const auto at = [&](std::uint32_t row, std::uint32_t s) { return 1 + row * segments + s % segments; };
    for (std::uint32_t s = 0; s < segments; ++s) {
        mesh.indices.insert(mesh.indices.end(), {0u, at(0, s), at(0, s + 1)});
        for (std::uint32_t row = 0; row + 1 < row_count; ++row)
            mesh.indices.insert(mesh.indices.end(), {at(row, s), at(row + 1, s), at(row + 1, s + 1), at(row, s),
                                                     at(row + 1, s + 1), at(row, s + 1)});
        mesh.indices.insert(mesh.indices.end(), {at(row_count - 1, s), south, at(row_count - 1, s + 1)});
    }
    return mesh;
}

/// Moves the vertex nearest to each of the capsule's six world-axis support points onto that point.
/// A tilted capsule's UV rings miss those points, and without them the mesh's box would be smaller than
/// world_aabb. The support points lie on the surface, so every vertex stays on it.
void snap_to_support_points(TriangleMesh& mesh, const Capsule& capsule) {
    for (int axis = 0; axis < 3; ++axis) {
        for (double sign : {-1.0, 1.0}) {
            const Vec3 direction = sign * Vec3::Unit(axis);
            const Vec3& end = direction.dot(capsule.p1) >= direction.dot(capsule.p0) ? capsule.p1 : capsule.p0;
            const Vec3 support = end + capsule.radius * direction;
            std::size_t nearest = 0;
            double best = std::numeric_limits<double>::infinity();
            for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
                const double d = (mesh.positions[i] - support).squaredNorm();
                if (d < best) {
                    best = d;
                    nearest = i;
                }
            }
            mesh.positions[nearest] = support;
            mesh.normals[nearest] = direction;
        }
    }
}

template <class... Ts>
struct Overloaded : Ts... {
    using Ts::operator()...;
};
template <class... Ts>
Overloaded(Ts...) -> Overloaded<Ts...>;

}  // namespace

TriangleMesh triangulate(const BoundingVolume& bv, const MeshDetail& detail) {
    return std::visit(
        Overloaded{
            [](const Aabb& box) {
                return box_mesh(Mat3::Identity(), [&](int bits) {
                    return Vec3(bits & 1 ? box.max.x() : box.min.x(), bits & 2 ? box.max.y() : box.min.y(),
                                bits & 4 ? box.max.z() : box.min.z());
                });
            },
            [](const Obb& box) { return box_mesh(box.rotation, [&](int bits) { return box.corner(bits); }); },
            [&](const Sphere& sphere) {
                return swept_sphere_mesh(sphere.center, sphere.center, sphere.radius, Mat3::Identity(), detail);
            },
            [&](const Capsule& capsule) {
                // A right-handed frame (u, v, w) with w along the axis; u from the world axis least
                // aligned with w, so the cross product is well conditioned.
                const Vec3 w = capsule.direction();
                Eigen::Index least = 0;
                w.cwiseAbs().minCoeff(&least);
                const Vec3 u = Vec3::Unit(least).cross(w).normalized();
                Mat3 frame;
                frame << u, w.cross(u), w;
                TriangleMesh mesh = swept_sphere_mesh(capsule.p0, capsule.p1, capsule.radius, frame, detail);
                snap_to_support_points(mesh, capsule);
                return mesh;
            },
        },
        bv);
}

}  // namespace hbvh
