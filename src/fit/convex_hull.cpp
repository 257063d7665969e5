// SPDX-License-Identifier: MIT
// Convex hull of sphere centres (our quickhull for small sets, qhull for the rest), and the hull-surface covariance.
#include "convex_hull.hpp"
#include "quickhull.hpp"

#include <algorithm>
#include <cstdio>
#include <limits>
#include <memory>
#include <optional>
#include <utility>

extern "C" {
#include <libqhull_r/qhull_ra.h>
}

#include "../memory/thread_scratch.hpp"
#include "../simd/wide_clones.hpp"

namespace hbvh::detail {
namespace {

/// qhull writes diagnostics (precision warnings, "initial simplex is flat") to the FILE it is given and
/// to stderr when given none. The library must never print, so every run gets this sink instead.
/// Opened once; stdio locks the FILE, so concurrent fits may share it.
FILE* null_sink() {
    static FILE* const sink = std::fopen("/dev/null", "w");
    return sink;
}

/// Adds Gottschalk's (1996, eq. in §4 "Fitting OBBs") contribution of triangle (p, q, r) to the running
/// sums: area-weighted second moments of a uniform density on the triangle.
/// Returns the triangle's area.
double add_triangle(const Vec3& p, const Vec3& q, const Vec3& r, double& area_sum, Vec3& weighted_centroid,
                    Mat3& second_moment) {
    const double area = 0.5 * (q - p).cross(r - p).norm();
    if (!(area > 0.0)) return 0.0;
    const Vec3 centroid = (p + q + r) / 3.0;
    area_sum += area;
    weighted_centroid += area * centroid;
    // E[x x^T] over the triangle = (9 m m^T + p p^T + q q^T + r r^T) / 12.
    second_moment += (area / 12.0) * (9.0 * centroid * centroid.transpose() + p * p.transpose() +
                                      q * q.transpose() + r * r.transpose());
    return area;
}

/// Largest faces first, merging normals within ~0.01 degree (Qt splits flat faces into triangles).
std::vector<Vec3> distinct_normals(std::vector<std::pair<double, Vec3>> faces) {
    std::stable_sort(faces.begin(), faces.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
    std::vector<Vec3> normals;
    normals.reserve(std::min(faces.size(), max_face_normals));
    for (const auto& [area, normal] : faces) {
        if (normals.size() >= max_face_normals) break;
        const bool seen = std::any_of(normals.begin(), normals.end(),
                                      [&](const Vec3& n) { return n.dot(normal) > 1.0 - 1e-8; });
        if (!seen) normals.push_back(normal);
    }
    return normals;
}

/// Every index 0..n-1: the fallback "hull" that keeps all spheres.
std::vector<std::uint32_t> all_indices(std::size_t n) {
    std::vector<std::uint32_t> indices(n);
    for (std::size_t i = 0; i < n; ++i) indices[i] = static_cast<std::uint32_t>(i);
    return indices;
}

}  // namespace

HBVH_WIDE_CLONES_INLINED bool outline_along(const HullSurface& surface, const Vec3& direction, OutlineScratch& scratch) {
    std::vector<std::uint32_t>& outline = scratch.outline;
    outline.clear();
    if (surface.empty()) return false;
    constexpr std::uint32_t none = std::numeric_limits<std::uint32_t>::max();
    const std::size_t triangle_count = surface.triangles.size();
    // Slots are 0..V-1 and F = 2V - 4, so V = F / 2 + 2.
    std::vector<std::uint32_t>& next_slot = scratch.next_slot;
    next_slot.assign(triangle_count / 2 + 2, none);
    // Faces parallel to the direction (a box's sides, seen along its face normal) have n.d = 0 up to rounding;
    // taking either sign would let the loop cross such a face diagonally, back and forth in projection. So
    // they count as turned away: they project to slivers at most 1e-9 of their size wide.
    const double parallel = 1e-9 * direction.norm();
    std::vector<unsigned char>& facing = scratch.facing;
    facing.resize(triangle_count);
    for (std::size_t t = 0; t < triangle_count; ++t) facing[t] = surface.normals[t].dot(direction) > parallel ? 1 : 0;
    std::size_t edges = 0;
    std::uint32_t start = none;
    for (std::size_t t = 0; t < triangle_count; ++t) {
        if (facing[t] == 0) continue;
        for (std::size_t k = 0; k < 3; ++k) {
            if (facing[surface.neighbors[t][k]] != 0) continue;
            const std::uint32_t from = surface.triangles[t][k];
            if (next_slot[from] != none) return false;  // two outline edges leave one vertex: not one loop
            next_slot[from] = surface.triangles[t][(k + 1) % 3];
            start = from;
            ++edges;
        }
    }
    if (start == none) return false;
    for (std::uint32_t v = start; outline.size() <= edges;) {
        outline.push_back(v);
        v = next_slot[v];
        if (v == none) return false;
        if (v == start) break;
    }
    return outline.size() == edges;  // the walk closed after every outline edge: one simple loop
}

Mat3 point_covariance(std::span<const Sphere> spheres, std::span<const std::uint32_t> indices) {
    const std::size_t count = indices.empty() ? spheres.size() : indices.size();
    auto at = [&](std::size_t i) -> const Vec3& { return spheres[indices.empty() ? i : indices[i]].center; };
    Vec3 mean = Vec3::Zero();
    for (std::size_t i = 0; i < count; ++i) mean += at(i);
    mean /= static_cast<double>(count);
    Mat3 covariance = Mat3::Zero();
    for (std::size_t i = 0; i < count; ++i) {
        const Vec3 d = at(i) - mean;
        covariance += d * d.transpose();
    }
    return covariance / static_cast<double>(count);
}

namespace {

/// The summary of a hull given as triangles over `points` (the centred centres).
HullSummary summary_of_triangles(std::span<const Vec3> points, const TriangleHull& hull) {
    HullSummary summary;
    double area_sum = 0.0;
    Vec3 weighted_centroid = Vec3::Zero();
    Mat3 second_moment = Mat3::Zero();
    std::vector<std::pair<double, Vec3>> faces;
    faces.reserve(hull.triangles.size());
    thread_local std::vector<std::uint32_t> slot_of;  // per thread and kept; quickhull sets only, so at most 4 KiB
    slot_of.assign(points.size(), 0);
    for (std::uint32_t slot = 0; slot < hull.vertices.size(); ++slot) slot_of[hull.vertices[slot]] = slot;
    HullSurface& surface = summary.surface;
    surface.neighbors = hull.neighbors;
    surface.triangles.reserve(hull.triangles.size());
    surface.normals.reserve(hull.triangles.size());
    for (const auto& [a, b, c] : hull.triangles) {
        const Vec3& p = points[a];
        const Vec3& q = points[b];
        const Vec3& r = points[c];
        const double area = add_triangle(p, q, r, area_sum, weighted_centroid, second_moment);
        const Vec3 normal = (q - p).cross(r - p).normalized();
        if (area > 0.0) faces.emplace_back(area, normal);
        surface.triangles.push_back({slot_of[a], slot_of[b], slot_of[c]});
        surface.normals.push_back(normal);
    }
    if (!(area_sum > 0.0)) return HullSummary{};
    summary.vertices = hull.vertices;
    const Vec3 hull_centroid = weighted_centroid / area_sum;
    summary.covariance = second_moment / area_sum - hull_centroid * hull_centroid.transpose();
    summary.face_normals = distinct_normals(std::move(faces));
    summary.is_solid = true;
    return summary;
}

/// The summary by qhull; not solid when qhull finds no 3-D hull.
HullSummary summary_by_qhull(std::span<const Vec3> points) {
    HullSummary summary;
    FILE* sink = null_sink();
    if (sink == nullptr) return summary;
    std::vector<coordT> coordinates(3 * points.size());
    for (std::size_t i = 0; i < points.size(); ++i)
        for (int k = 0; k < 3; ++k) coordinates[3 * i + static_cast<std::size_t>(k)] = points[i][k];

    auto state = std::make_unique<qhT>();
    qhT* qh = state.get();
    qh_zero(qh, sink);
    // 'Qt' triangulates merged facets so that every facet is a triangle for the area weighting. 'Q5' skips
    // qh_check_maxout, the pass over every point that finds the outer planes' offsets for qhull's own output and
    // checks; the facets, their normals and vertices, which are all read here, do not depend on it. It was 6 % of
    // qhull's time on the cannon, and the trees of 22 inputs came out byte for byte the same without it.
    char command[] = "qhull Qt Q5";
    const int exit_code = qh_new_qhull(qh, 3, static_cast<int>(points.size()), coordinates.data(), False, command,
                                       nullptr, sink);
    if (exit_code == 0) {
        double area_sum = 0.0;
        Vec3 weighted_centroid = Vec3::Zero();
        Mat3 second_moment = Mat3::Zero();
        std::vector<std::pair<double, Vec3>> faces;
        facetT* facet = nullptr;
        FORALLfacets {
            // Triangulated output has three vertices per facet; fan anything else to stay safe.
            const int vertex_count = qh_setsize(qh, facet->vertices);
            if (vertex_count < 3) continue;
            auto vertex_point = [&](int i) {
                const auto* vertex = static_cast<vertexT*>(SETelem_(facet->vertices, i));
                return Vec3(vertex->point[0], vertex->point[1], vertex->point[2]);
            };
            const Vec3 first = vertex_point(0);
            double face_area = 0.0;
            for (int i = 1; i + 1 < vertex_count; ++i)
                face_area += add_triangle(first, vertex_point(i), vertex_point(i + 1), area_sum, weighted_centroid,
                                          second_moment);
            const Vec3 normal(facet->normal[0], facet->normal[1], facet->normal[2]);
            if (face_area > 0.0 && normal.norm() > 0.5) faces.emplace_back(face_area, normal.normalized());
        }
        vertexT* vertex = nullptr;
        FORALLvertices {
            const int id = qh_pointid(qh, vertex->point);
            if (id >= 0 && static_cast<std::size_t>(id) < points.size())
                summary.vertices.push_back(static_cast<std::uint32_t>(id));
        }
        if (area_sum > 0.0 && summary.vertices.size() >= 4) {
            const Vec3 hull_centroid = weighted_centroid / area_sum;
            summary.covariance = second_moment / area_sum - hull_centroid * hull_centroid.transpose();
            summary.face_normals = distinct_normals(std::move(faces));
            summary.is_solid = true;
        }
    }
    qh_freeqhull(qh, !qh_ALL);
    int current_long = 0;
    int total_long = 0;
    qh_memfreeshort(qh, &current_long, &total_long);
    return summary;
}

}  // namespace

HullSummary summarize_hull(std::span<const Sphere> spheres, HullMethod method) {
    HullSummary summary;
    // Fewer than four points cannot span a solid.
    if (spheres.size() >= 4) {
        // Centre the points first: precision thresholds (ours and qhull's) are relative to the largest
        // coordinate, so a small cluster far from the origin (1e6 away) would otherwise look flat.
        Vec3 mean = Vec3::Zero();
        for (const Sphere& s : spheres) mean += s.center;
        mean /= static_cast<double>(spheres.size());
        thread_local std::vector<Vec3> points;  // per thread and kept (memory/thread_scratch.hpp)
        const ReleaseIfLarge release(points);
        points.clear();
        for (const Sphere& s : spheres) points.push_back(s.center - mean);
        // Small sets by our own quickhull, which returns nothing whenever rounding could mislead it;
        // qhull, with its facet merging, takes those and the large sets, except sets flat within rounding,
        // where it can find no solid either (docs/fitting.md, "Flat sets without qhull").
        std::optional<TriangleHull> triangles;
        bool flat_within_rounding = false;
        if (method == HullMethod::automatic && points.size() <= quickhull_max_points)
            triangles = quickhull(points, &flat_within_rounding);
        if (triangles)
            summary = summary_of_triangles(points, *triangles);
        else if (!flat_within_rounding)
            summary = summary_by_qhull(points);
    }
    if (!summary.is_solid) {
        // Flat boxes, collinear points, duplicates: no 3-D hull, so use the raw centres.
        summary = HullSummary{};
        summary.vertices = all_indices(spheres.size());
        summary.covariance = point_covariance(spheres);
    }
    return summary;
}

}  // namespace hbvh::detail
