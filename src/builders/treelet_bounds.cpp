// SPDX-License-Identifier: MIT
#include "treelet_bounds.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>

#include "../fit/quickhull.hpp"
#include "hbvh/geometry/bounding_volume.hpp"

namespace hbvh::detail {

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

TreeletBounds::TreeletBounds(std::vector<std::vector<Vec3>> unit_points, double margin, const VolumePolicy& policy)
    : points_(std::size_t{1} << unit_points.size()), bound_(points_.size(), -1.0), margin_(std::max(0.0, margin)) {
    double weight = std::numeric_limits<double>::infinity();
    for (BvType kind : {BvType::aabb, BvType::obb, BvType::sphere, BvType::capsule})
        if (policy.is_allowed(kind)) weight = std::min(weight, policy.weight_of(kind));
    // The hull's volume carries rounding of a few ulps of its coordinates, and a fit's volume too: a
    // millionth off keeps the bound below.
    scale_ = weight * (policy.measure == NodeMeasure::volume ? 1.0 : 8.0) * (1.0 - 1e-6);
    for (std::size_t i = 0; i < unit_points.size(); ++i) {
        const std::uint32_t mask = 1u << i;
        points_[mask] = std::move(unit_points[i]);
        hull_of(mask);
    }
}

double TreeletBounds::bound(std::uint32_t mask) {
    if (bound_[mask] < 0.0) {
        const std::uint32_t rest = mask & (mask - 1u);
        const std::uint32_t lowest = mask & ~rest;
        (void)bound(rest);  // its hull's vertices
        points_[mask] = points_[rest];
        points_[mask].insert(points_[mask].end(), points_[lowest].begin(), points_[lowest].end());
        hull_of(mask);
    }
    return bound_[mask];
}

void TreeletBounds::hull_of(std::uint32_t mask) {
    std::vector<Vec3>& points = points_[mask];
    const double m = margin_;
    const double ball = 4.0 / 3.0 * std::numbers::pi * m * m * m;
    bound_[mask] = ball * scale_;
    if (points.size() < 4 || points.size() > quickhull_max_points) return;
    const std::optional<TriangleHull> hull = quickhull(points);
    if (!hull) return;
    double six_volume = 0.0;
    double twice_area = 0.0;
    double twice_edge_sum = 0.0;  // each edge is seen from both of its triangles
    const Vec3 origin = points[hull->vertices.front()];
    std::vector<Vec3>& unit_normals = unit_normals_;
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
            for (int k = 0; k < 3; ++k) {
                const double chord = (unit_normals[i] - unit_normals[hull->neighbors[i][k]]).norm();
                twice_edge_sum += (points[t[(k + 1) % 3]] - points[t[k]]).norm() * chord;
            }
        }
    }
    const double grown = six_volume / 6.0 + twice_area / 2.0 * m + twice_edge_sum / 4.0 * m * m + ball;
    bound_[mask] = std::max(0.0, grown * scale_);
    std::vector<Vec3> vertices;
    vertices.reserve(hull->vertices.size());
    for (std::uint32_t v : hull->vertices) vertices.push_back(points[v]);
    points = std::move(vertices);
}

}  // namespace hbvh::detail
