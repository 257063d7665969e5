// SPDX-License-Identifier: MIT
// Tessellation of boxes, spheres and capsules into triangle meshes with exact normals.
#include "hbvh/io/bv_mesh.hpp"

#include <cmath>
#include <utility>
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

/// cos and sin that are exact at the quarter turns. Those angles give the world-axis extremes of
/// spheres, and rounding there would make the mesh's box differ from world_aabb.
std::pair<double, double> exact_cos_sin(double angle) {
    const double quarter_turns = angle / (0.5 * std::numbers::pi);
    const double nearest = std::round(quarter_turns);
    if (std::abs(quarter_turns - nearest) < 1e-12) {
        static constexpr std::array<std::pair<double, double>, 4> axes{{{1, 0}, {0, 1}, {-1, 0}, {0, -1}}};
        return axes[static_cast<std::size_t>((static_cast<long long>(nearest) % 4 + 4) % 4)];
    }
    return {std::cos(angle), std::sin(angle)};
}

/// Adds `value` to the sorted grid coordinates `values`, dropping the uniform coordinates within `merge`
/// of it (on a circle of circumference `period`, or on a line when period is 0) so no sliver bands appear.
void require_coordinate(std::vector<double>& values, std::vector<bool>& required, double value, double period,
                        double merge) {
    for (std::size_t i = 0; i < values.size();) {
        double gap = std::abs(values[i] - value);
        if (period > 0.0) gap = std::min(gap, period - gap);
        // Within a nanoradian the existing line serves: the touching point then moves by ~1e-18 r along
        // its axis (it is an extreme, so the error is second order), and no near-duplicate row appears.
        if (gap < 1e-9) {
            required[i] = true;
            return;
        }
        if (gap < merge && !required[i]) {
            values.erase(values.begin() + static_cast<std::ptrdiff_t>(i));
            required.erase(required.begin() + static_cast<std::ptrdiff_t>(i));
        } else {
            ++i;
        }
    }
    const auto at = std::lower_bound(values.begin(), values.end(), value);
    required.insert(required.begin() + (at - values.begin()), true);
    values.insert(at, value);
}

/// A latitude-longitude grid on the unit sphere: polar angles strictly between the poles (always
/// including the equator) and azimuths in [0, 2 pi), both ascending.
struct SphereGrid {
    std::vector<double> thetas;
    std::vector<double> phis;
    std::vector<bool> theta_required;
    std::vector<bool> phi_required;

    explicit SphereGrid(const MeshDetail& detail) {
        const std::uint32_t segments = std::max<std::uint32_t>(4, (detail.segments + 3) / 4 * 4);
        const std::uint32_t rings = std::max<std::uint32_t>(2, (detail.rings + 1) / 2 * 2);
        for (std::uint32_t ring = 1; ring < rings; ++ring) thetas.push_back(std::numbers::pi * ring / rings);
        for (std::uint32_t s = 0; s < segments; ++s) phis.push_back(2.0 * std::numbers::pi * s / segments);
        theta_required.assign(thetas.size(), false);
        phi_required.assign(phis.size(), false);
        theta_required[rings / 2 - 1] = true;  // the equator, where a capsule's cylinder attaches
    }

    /// Makes the unit direction `d` (in the frame u, v, w) a grid vertex, unless it is a pole.
    void require_direction(const Vec3& d) {
        const double theta = std::acos(std::clamp(d.z(), -1.0, 1.0));
        if (theta <= 0.0 || theta >= std::numbers::pi) return;
        double phi = std::atan2(d.y(), d.x());
        if (phi < 0.0) phi += 2.0 * std::numbers::pi;
        const double theta_merge = 0.25 * std::numbers::pi / static_cast<double>(thetas.size() + 1);
        const double phi_merge = 0.25 * 2.0 * std::numbers::pi / static_cast<double>(phis.size());
        require_coordinate(thetas, theta_required, theta, 0.0, theta_merge);
        require_coordinate(phis, phi_required, phi, 2.0 * std::numbers::pi, phi_merge);
    }
};

/// A sphere (p0 == p1) or capsule around the segment p0-p1 with radius r, on `grid` in the right-handed
/// frame (u, v, w) = columns of `frame`. Rows with theta <= pi/2 are centred on p1, the others on p0;
/// a capsule repeats the equator row on both ends, and the band between the copies is the cylinder.
TriangleMesh swept_sphere_mesh(const Vec3& p0, const Vec3& p1, double radius, const Mat3& frame,
                               const SphereGrid& grid) {
    const bool has_cylinder = p0 != p1;
    const Vec3 u = frame.col(0), v = frame.col(1), w = frame.col(2);
    const auto segments = static_cast<std::uint32_t>(grid.phis.size());
    TriangleMesh mesh;
    const auto add_vertex = [&](const Vec3& centre, const Vec3& direction) {
        mesh.positions.push_back(centre + radius * direction);
        mesh.normals.push_back(direction);
    };

    // Stage 1: vertices. North pole, the rows (the equator twice for a capsule), south pole.
    add_vertex(p1, w);
    std::uint32_t row_count = 0;
    for (double theta : grid.thetas) {
        const auto [cos_theta, sin_theta] = exact_cos_sin(theta);
        const bool equator = cos_theta == 0.0;
        const int copies = (equator && has_cylinder) ? 2 : 1;
        for (int copy = 0; copy < copies; ++copy) {
            const Vec3& centre = (cos_theta >= 0.0 && copy == 0) ? p1 : p0;
            for (double phi : grid.phis) {
                const auto [cos_phi, sin_phi] = exact_cos_sin(phi);
                add_vertex(centre, sin_theta * (cos_phi * u + sin_phi * v) + cos_theta * w);
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
                // World-aligned frame: the uniform grid already holds the six extremes.
                return swept_sphere_mesh(sphere.center, sphere.center, sphere.radius, Mat3::Identity(),
                                         SphereGrid(detail));
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
                // A tilted capsule touches its world AABB at points between the uniform grid lines; add
                // grid lines through them, so the mesh's box is world_aabb and no vertex leaves the surface.
                // The touching point in direction e is end + r e, on the hemisphere facing e.
                SphereGrid grid(detail);
                for (int axis = 0; axis < 3; ++axis)
                    for (double sign : {-1.0, 1.0}) grid.require_direction(frame.transpose() * (sign * Vec3::Unit(axis)));
                return swept_sphere_mesh(capsule.p0, capsule.p1, capsule.radius, frame, grid);
            },
        },
        bv);
}

}  // namespace hbvh
