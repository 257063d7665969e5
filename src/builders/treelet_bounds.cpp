// SPDX-License-Identifier: MIT
#include "treelet_bounds.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>

#include "../fit/hull_2d.hpp"
#include "../fit/quickhull.hpp"
#include "hbvh/geometry/bounding_volume.hpp"

namespace hbvh::detail {
namespace {

/// The bound of points that span no solid (or fewer than four): every volume around them holds the polygon
/// Q of their projections on a plane through them, grown by the margin less their largest distance e from
/// that plane (Q lies within e of their hull), and a polygon of area A and perimeter P grown by m has volume
/// 2 A m + (pi / 2) P m^2 + 4/3 pi m^3 (Steiner's formula with every edge's exterior angle pi; a segment is
/// a polygon of area 0 and perimeter twice its length, a capsule). 0 where the points are not that flat.
double flat_bound(std::span<const Vec3> points, double margin) {
    if (points.empty()) return 0.0;
    // The plane: through the first point, the farthest from it, and the farthest from their line (any plane
    // through that line where all are on it).
    const Vec3 origin = points.front();
    Vec3 far = origin;
    for (const Vec3& p : points)
        if ((p - origin).squaredNorm() > (far - origin).squaredNorm()) far = p;
    const double extent = (far - origin).norm();
    if (!(extent > 0.0)) return 0.0;  // one point: the ball bound says it all
    const Vec3 along = (far - origin) / extent;
    Vec3 normal = along.unitOrthogonal();
    double widest = 0.0;
    for (const Vec3& p : points) {
        const Vec3 cross = along.cross(p - origin);
        if (cross.norm() > widest) {
            widest = cross.norm();
            normal = cross / widest;
        }
    }
    const Vec3 across = normal.cross(along);
    double distance = 0.0;
    // Per thread and kept: grown_hull passes at most quickhull_max_points points, 16 KiB of projections.
    thread_local std::vector<Eigen::Vector2d> projected, polygon;
    projected.clear();
    for (const Vec3& p : points) {
        distance = std::max(distance, std::abs(normal.dot(p - origin)));
        projected.emplace_back(along.dot(p - origin), across.dot(p - origin));
    }
    // Rounding in the projection is a few ulps of the extent; the margin left must cover it too.
    const double m = margin - distance - 1e-12 * extent;
    if (!(m > 0.0)) return 0.0;
    hull_2d(projected, polygon);
    double twice_area = 0.0;
    double perimeter = 0.0;
    for (std::size_t i = 0; i < polygon.size(); ++i) {
        const Eigen::Vector2d& a = polygon[i];
        const Eigen::Vector2d& b = polygon[(i + 1) % polygon.size()];
        twice_area += a.x() * b.y() - a.y() * b.x();
        perimeter += (b - a).norm();
    }
    if (polygon.size() < 3) twice_area = 0.0;  // a segment (there and back) or a point
    return twice_area * m + std::numbers::pi / 2.0 * perimeter * m * m + 4.0 / 3.0 * std::numbers::pi * m * m * m;
}

/// The hull of `points` grown by `margin`: its bound and its vertices.
SetBound grown_hull(std::vector<Vec3> points, double margin, double scale) {
    SetBound out;
    out.margin = margin;
    const double m = margin;
    const double ball = 4.0 / 3.0 * std::numbers::pi * m * m * m;
    out.bound = ball * scale;
    if (points.size() > quickhull_max_points) {
        out.points = std::move(points);
        return out;
    }
    const std::optional<TriangleHull> hull = points.size() < 4 ? std::nullopt : quickhull(points);
    if (!hull) {  // flat, or no solid the quickhull builds: the polygon's bound where it is flat
        out.bound = std::max(out.bound, flat_bound(points, margin) * scale);
        out.points = std::move(points);
        return out;
    }
    double six_volume = 0.0;
    double twice_area = 0.0;
    double twice_edge_sum = 0.0;  // each edge is seen from both of its triangles
    const Vec3 origin = points[hull->vertices.front()];
    thread_local std::vector<Vec3> unit_normals;
    unit_normals.resize(hull->triangles.size());
    for (std::size_t i = 0; i < hull->triangles.size(); ++i) {
        const auto& t = hull->triangles[i];
        six_volume += (points[t[0]] - origin).dot((points[t[1]] - origin).cross(points[t[2]] - origin));
        const Vec3 normal = (points[t[1]] - points[t[0]]).cross(points[t[2]] - points[t[0]]);
        const double length = normal.norm();
        twice_area += length;
        unit_normals[i] = length > 0.0 ? Vec3(normal / length) : Vec3::Zero();
    }
    if (m > 0.0) {
        // An edge's exterior angle is at least the chord between its faces' unit normals (2 sin(angle / 2)).
        for (std::size_t i = 0; i < hull->triangles.size(); ++i) {
            const auto& t = hull->triangles[i];
            for (std::size_t k = 0; k < 3; ++k) {
                const double chord = (unit_normals[i] - unit_normals[hull->neighbors[i][k]]).norm();
                twice_edge_sum += (points[t[(k + 1) % 3]] - points[t[k]]).norm() * chord;
            }
        }
    }
    const double grown = six_volume / 6.0 + twice_area / 2.0 * m + twice_edge_sum / 4.0 * m * m + ball;
    out.bound = std::max(0.0, grown * scale);
    out.points.reserve(hull->vertices.size());
    for (std::uint32_t v : hull->vertices) out.points.push_back(points[v]);
    return out;
}

}  // namespace

double least_radius(std::span<const Primitive> primitives, std::span<const std::uint32_t> set) {
    double least = std::numeric_limits<double>::infinity();
    std::vector<Sphere> spheres;
    for (std::uint32_t p : set) {
        spheres.clear();
        append_generating_spheres(primitives[p].volume, spheres);
        for (const Sphere& sphere : spheres) least = std::min(least, sphere.radius);
    }
    return least;
}

std::vector<Vec3> points_inside(std::span<const Primitive> primitives, std::span<const std::uint32_t> set,
                                double margin) {
    std::vector<Vec3> points;
    std::vector<Sphere> spheres;
    for (std::uint32_t p : set) {
        spheres.clear();
        append_generating_spheres(primitives[p].volume, spheres);
        for (const Sphere& sphere : spheres) {
            const double reach = sphere.radius - margin;
            if (!(reach > 0.0)) {
                points.push_back(sphere.center);
                continue;
            }
            for (int axis = 0; axis < 3; ++axis)
                for (double side : {-1.0, 1.0}) {
                    Vec3 point = sphere.center;
                    point[axis] += side * reach;
                    points.push_back(point);
                }
        }
    }
    return points;
}

double bound_scale(const VolumePolicy& policy) {
    double weight = std::numeric_limits<double>::infinity();
    for (BvType kind : {BvType::aabb, BvType::obb, BvType::sphere, BvType::capsule})
        if (policy.is_allowed(kind)) weight = std::min(weight, policy.weight_of(kind));
    return weight * (policy.measure == NodeMeasure::volume ? 1.0 : 8.0) * (1.0 - 1e-6);
}

SetBound bound_set(std::span<const Primitive> primitives, std::span<const std::uint32_t> set, double scale) {
    const double margin = std::max(0.0, least_radius(primitives, set));
    return grown_hull(points_inside(primitives, set, margin), margin, scale);
}

SetBound bound_union(std::span<const Primitive> primitives, const SetBound& a, std::span<const std::uint32_t> set_a,
                     const SetBound& b, std::span<const std::uint32_t> set_b, double scale) {
    const double margin = std::min(a.margin, b.margin);
    std::vector<Vec3> points = a.margin == margin ? a.points : points_inside(primitives, set_a, margin);
    const std::vector<Vec3> more = b.margin == margin ? b.points : points_inside(primitives, set_b, margin);
    points.insert(points.end(), more.begin(), more.end());
    return grown_hull(std::move(points), margin, scale);
}

}  // namespace hbvh::detail
