// SPDX-License-Identifier: MIT
// capsule_volume_lower_bound: diameter and smallest in-plane widths of the set (see the header's proof).
#include "capsule_bound.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "../memory/thread_scratch.hpp"
#include "hull_2d.hpp"

namespace hbvh::detail {
namespace {

/// Smallest width of a convex polygon (counter-clockwise, no repeated points): attained perpendicular to
/// one of its edges, so the widths across the edges are the only ones tried. Brute force over every vertex
/// for small polygons, the antipodal vertex by rotating calipers above (a flat ring of 10^5 spheres has a
/// 2-D hull of 10^5 points, and the brute force was quadratic in it).
double min_width(const std::vector<Eigen::Vector2d>& hull, std::vector<EdgeExtremes>& extremes) {
    if (hull.size() < 3) return 0.0;  // a segment or a point has no width
    const bool brute_force = hull.size() <= calipers_above;
    if (!brute_force) edge_extremes(hull, extremes);
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < hull.size(); ++i) {
        const Eigen::Vector2d edge = hull[(i + 1) % hull.size()] - hull[i];
        const double length = edge.norm();
        if (!(length > 0.0)) continue;
        const Eigen::Vector2d normal(-edge.y() / length, edge.x() / length);
        double far = 0.0;
        if (brute_force) {
            for (const Eigen::Vector2d& p : hull) far = std::max(far, std::abs((p - hull[i]).dot(normal)));
        } else {
            far = std::abs((hull[extremes[i].farthest_across] - hull[i]).dot(normal));
        }
        best = std::min(best, far);
    }
    return std::isfinite(best) ? best : 0.0;
}

/// Normals of the planes tried in a frame: its axes, and the diagonals of its faces and of the cube. For a
/// box-like set with sides a >= b >= c along the frame, the plane containing a and the diagonal of b and
/// c has smallest width min(a, (b + c) / sqrt 2), close to the sqrt(b^2 + c^2) a capsule along a needs;
/// the frame's own planes only give b.
const std::array<Vec3, 13>& plane_normals() {
    static const std::array<Vec3, 13> normals = [] {
        std::array<Vec3, 13> n{Vec3(1, 0, 0),  Vec3(0, 1, 0),  Vec3(0, 0, 1),  Vec3(0, 1, 1),  Vec3(0, 1, -1),
                               Vec3(1, 0, 1),  Vec3(1, 0, -1), Vec3(1, 1, 0),  Vec3(1, -1, 0), Vec3(1, 1, 1),
                               Vec3(1, 1, -1), Vec3(1, -1, 1), Vec3(-1, 1, 1)};
        for (Vec3& v : n) v.normalize();
        return n;
    }();
    return normals;
}

/// The farthest reach of any pair, |c_a - c_b| + r_a + r_b, over the pairs among `candidates` (indices).
double farthest_pair(std::span<const Sphere> spheres, std::span<const std::size_t> candidates) {
    double diameter = 0.0;
    for (std::size_t i = 0; i < candidates.size(); ++i) {
        const Sphere& a = spheres[candidates[i]];
        diameter = std::max(diameter, 2.0 * a.radius);
        for (std::size_t j = i + 1; j < candidates.size(); ++j) {
            const Sphere& b = spheres[candidates[j]];
            diameter = std::max(diameter, (a.center - b.center).norm() + a.radius + b.radius);
        }
    }
    return diameter;
}

/// The set's diameter D, or a lower bound of it, which keeps the capsule bound valid (only weaker).
/// Exact over all pairs for small sets; for large ones (the top nodes of big scenes, where the quadratic
/// loop was a tenth of a whole `split` build) the farthest pair among the spheres extremal along the 13
/// plane normals, which are actual pairs of the set and in practice within a few per cent of D.
double diameter_lower_bound(std::span<const Sphere> spheres) {
    constexpr std::size_t exact_up_to = 64;
    std::vector<std::size_t> candidates;
    if (spheres.size() <= exact_up_to) {
        candidates.resize(spheres.size());
        for (std::size_t i = 0; i < spheres.size(); ++i) candidates[i] = i;
        return farthest_pair(spheres, candidates);
    }
    for (const Vec3& n : plane_normals()) {
        std::size_t low = 0;
        std::size_t high = 0;
        for (std::size_t i = 1; i < spheres.size(); ++i) {
            const double t = spheres[i].center.dot(n);
            if (t - spheres[i].radius < spheres[low].center.dot(n) - spheres[low].radius) low = i;
            if (t + spheres[i].radius > spheres[high].center.dot(n) + spheres[high].radius) high = i;
        }
        candidates.push_back(low);
        candidates.push_back(high);
    }
    return farthest_pair(spheres, candidates);
}

}  // namespace

double capsule_volume_lower_bound(const SphereProxy& proxy, std::span<const Mat3> planes, double enough) {
    if (proxy.spheres.empty()) return 0.0;
    // Relative to one centre, so that rounding scales with the set's size, not its distance from the origin.
    const Vec3 origin = proxy.spheres.front().center;
    double min_radius = std::numeric_limits<double>::infinity();
    double max_radius = 0.0;
    for (const Sphere& a : proxy.spheres) {
        min_radius = std::min(min_radius, a.radius);
        max_radius = std::max(max_radius, a.radius);
    }
    const double diameter = diameter_lower_bound(proxy.spheres);

    auto volume_at = [&](double radius) {
        const double length = std::max(0.0, diameter - 2.0 * radius);
        return std::numbers::pi * radius * radius * length + 4.0 / 3.0 * std::numbers::pi * radius * radius * radius;
    };
    // Every sphere's centre lies in the hull of the hull points, and each sphere is at least min_radius
    // thick, so the set's width along u is at least the hull points' width plus 2 min_radius.
    double radius = max_radius;
    thread_local std::vector<Eigen::Vector2d> hull;  // per thread and kept (memory/thread_scratch.hpp)
    thread_local std::vector<EdgeExtremes> extremes;
    thread_local OutlineScratch scratch;
    const ReleaseIfLarge release(hull, extremes, scratch);
    for (const Mat3& frame : planes)
        for (const Vec3& local_normal : plane_normals()) {
            const Mat3 basis = frame_from_axis(frame * local_normal);
            hull_outline(proxy, basis, origin, hull, scratch);
            radius = std::max(radius, 0.5 * min_width(hull, extremes) + min_radius);
            // The bound only grows from here; once it is enough the other planes cannot change the answer.
            if (volume_at(radius) >= enough) return volume_at(radius);
        }
    return volume_at(radius);
}

}  // namespace hbvh::detail
