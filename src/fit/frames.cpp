// SPDX-License-Identifier: MIT
// Candidate orientations (principal axes, DiTO, face-flush, local refinement) and per-frame box evaluation.
#include "frames.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <span>

#include <Eigen/Eigenvalues>

#include "../memory/thread_scratch.hpp"
#include "../simd/wide_clones.hpp"
#include "hull_2d.hpp"
#include "rounding_pad.hpp"
#include "sphere_extents.hpp"

namespace hbvh::detail {
namespace {

constexpr double infinity = std::numeric_limits<double>::infinity();

/// Any unit vector perpendicular to the unit vector `u`: cross with the world axis least aligned with it.
Vec3 any_perpendicular(const Vec3& u) {
    Eigen::Index least = 0;
    u.cwiseAbs().minCoeff(&least);
    return u.cross(Vec3::Unit(least)).normalized();
}

constexpr std::size_t dito_direction_count = 13;

/// The 13 directions of DiTO-26 (Larsson & Källberg 2011, §2): the face, edge and vertex normals of
/// a cube, one of each antipodal pair. Normalised so that support values with radii are distances.
const std::array<Vec3, dito_direction_count>& dito_normals() {
    static const std::array<Vec3, dito_direction_count> normals = [] {
        std::array<Vec3, dito_direction_count> n{
            Vec3(1, 0, 0), Vec3(0, 1, 0),  Vec3(0, 0, 1),  Vec3(1, 1, 1),  Vec3(1, 1, -1), Vec3(1, -1, 1), Vec3(1, -1, -1),
            Vec3(1, 1, 0), Vec3(1, -1, 0), Vec3(1, 0, 1),  Vec3(1, 0, -1), Vec3(0, 1, 1),  Vec3(0, 1, -1)};
        for (Vec3& v : n) v.normalize();
        return n;
    }();
    return normals;
}

/// The extent of points (xs[i], ys[i]) along the unit `d` and across it (along (-d.y, d.x)): low and high of
/// each, by a pass over every point, two per step in SSE2 lanes. Each coordinate is x * d.x + y * d.y, the
/// products and sum Vector2d::dot forms, and min and max are exact, so the lanes change no value.
struct PolygonExtent {
    double low_along, high_along, low_across, high_across;
};

PolygonExtent polygon_extent(std::span<const double> xs, std::span<const double> ys, const Eigen::Vector2d& d) {
    using Pair = Eigen::Array2d;
    const std::size_t count = xs.size();
    Pair low_along = Pair::Constant(infinity), high_along = Pair::Constant(-infinity);
    Pair low_across = Pair::Constant(infinity), high_across = Pair::Constant(-infinity);
    std::size_t i = 0;
    for (; i + 2 <= count; i += 2) {
        const Pair x = Pair::Map(xs.data() + i);
        const Pair y = Pair::Map(ys.data() + i);
        const Pair along = x * d.x() + y * d.y();
        const Pair across = x * -d.y() + y * d.x();
        low_along = low_along.min(along), high_along = high_along.max(along);
        low_across = low_across.min(across), high_across = high_across.max(across);
    }
    PolygonExtent e{std::min(low_along[0], low_along[1]), std::max(high_along[0], high_along[1]),
                    std::min(low_across[0], low_across[1]), std::max(high_across[0], high_across[1])};
    for (; i < count; ++i) {
        const double along = xs[i] * d.x() + ys[i] * d.y();
        const double across = xs[i] * -d.y() + ys[i] * d.x();
        e.low_along = std::min(e.low_along, along), e.high_along = std::max(e.high_along, along);
        e.low_across = std::min(e.low_across, across), e.high_across = std::max(e.high_across, across);
    }
    return e;
}

/// Squared distance from `p` to the line through `a` with unit direction `u`.
double squared_distance_to_line(const Vec3& p, const Vec3& a, const Vec3& u) {
    const Vec3 d = p - a;
    return (d - d.dot(u) * u).squaredNorm();
}

}  // namespace

Mat3 proper_frame(const Mat3& axes) {
    Vec3 x = axes.col(0);
    x = x.norm() > 0.0 ? Vec3(x.normalized()) : Vec3::UnitX();
    Vec3 y = axes.col(1) - axes.col(1).dot(x) * x;
    // A column that is (nearly) parallel to the first carries no orientation; pick any perpendicular.
    // The test is relative: callers pass unnormalised cross products, tiny for tiny inputs.
    y = y.norm() > 1e-12 * axes.col(1).norm() ? Vec3(y.normalized()) : any_perpendicular(x);
    Mat3 frame;
    frame.col(0) = x;
    frame.col(1) = y;
    frame.col(2) = x.cross(y);  // completes a right-handed frame, so det = +1
    return frame;
}

Mat3 principal_frame(const Mat3& covariance) {
    const Eigen::SelfAdjointEigenSolver<Mat3> solver(covariance);
    if (solver.info() != Eigen::Success) return Mat3::Identity();
    // Eigen sorts eigenvalues ascending; put the largest spread first.
    Mat3 axes;
    axes.col(0) = solver.eigenvectors().col(2);
    axes.col(1) = solver.eigenvectors().col(1);
    axes.col(2) = solver.eigenvectors().col(0);
    return proper_frame(axes);
}

Mat3 frame_from_axis(const Vec3& axis) {
    if (!(axis.norm() > 0.0)) return Mat3::Identity();
    const Vec3 u = axis.normalized();
    Mat3 axes;
    axes.col(0) = u;
    axes.col(1) = any_perpendicular(u);
    axes.col(2) = Vec3::Zero();
    return proper_frame(axes);
}

std::vector<Mat3> dito_frames(std::span<const Sphere> spheres) {
    // Stage 1: extremal spheres along each fixed direction (support value c.n +- r), each sphere once (the same
    // sphere is often extremal along several directions). The stages below take the first of equal values in
    // list order, which a repeat never is, so leaving repeats out changes no frame and spares their pairs.
    std::vector<Vec3> extremal;
    std::array<const Sphere*, 2 * dito_direction_count> taken{};
    std::size_t taken_count = 0;
    const auto take = [&](const Sphere* s) {
        const std::span<const Sphere* const> seen = std::span(taken).first(taken_count);
        if (std::ranges::find(seen, s) != seen.end()) return;
        taken[taken_count++] = s;
        extremal.push_back(s->center);
    };
    extremal.reserve(2 * dito_direction_count);
    for (const Vec3& n : dito_normals()) {
        double low = infinity;
        double high = -infinity;
        const Sphere* low_sphere = &spheres.front();
        const Sphere* high_sphere = &spheres.front();
        for (const Sphere& s : spheres) {
            const double t = s.center.dot(n);
            if (t - s.radius < low) low = t - s.radius, low_sphere = &s;
            if (t + s.radius > high) high = t + s.radius, high_sphere = &s;
        }
        take(low_sphere);
        take(high_sphere);
    }

    // Stage 2: the farthest pair among the extremal points is the first triangle edge. DiTO only compares
    // the pairs along one direction; all pairs of at most 26 points is still cheap and never worse.
    std::size_t a = 0;
    std::size_t b = 0;
    double farthest = 0.0;
    for (std::size_t i = 0; i < extremal.size(); ++i)
        for (std::size_t j = i + 1; j < extremal.size(); ++j) {
            const double d = (extremal[i] - extremal[j]).squaredNorm();
            if (d > farthest) farthest = d, a = i, b = j;
        }
    if (!(farthest > 0.0)) return {};  // all centres coincide: every frame is equally good
    // Below this (relative to the set's spread) a triangle or tetrahedron counts as flat.
    const double tiny = 1e-12 * std::sqrt(farthest);
    const Vec3 p0 = extremal[a];
    const Vec3 p1 = extremal[b];
    const Vec3 u = (p1 - p0).normalized();

    // Stage 3: the extremal point farthest from that line closes the base triangle.
    std::size_t c = 0;
    double off_line = 0.0;
    for (std::size_t i = 0; i < extremal.size(); ++i) {
        const double d = squared_distance_to_line(extremal[i], p0, u);
        if (d > off_line) off_line = d, c = i;
    }
    if (!(std::sqrt(off_line) > tiny)) return {frame_from_axis(u)};  // collinear: only the line's direction matters
    const Vec3 p2 = extremal[c];
    const Vec3 normal = (p1 - p0).cross(p2 - p0).normalized();

    // Stage 4: the apexes above and below the base plane make a ditetrahedron of up to 7 triangles.
    std::vector<std::array<Vec3, 3>> triangles;
    triangles.reserve(7);
    triangles.push_back({p0, p1, p2});
    std::size_t top = 0;
    std::size_t bottom = 0;
    for (std::size_t i = 0; i < extremal.size(); ++i) {
        const double h = (extremal[i] - p0).dot(normal);
        if (h > (extremal[top] - p0).dot(normal)) top = i;
        if (h < (extremal[bottom] - p0).dot(normal)) bottom = i;
    }
    for (std::size_t apex : {top, bottom}) {
        const Vec3 q = extremal[apex];
        if (!(std::abs((q - p0).dot(normal)) > tiny)) continue;
        triangles.push_back({p0, p1, q});
        triangles.push_back({p1, p2, q});
        triangles.push_back({p2, p0, q});
    }

    // Stage 5: each edge of each triangle, with the triangle's normal, spans one frame.
    std::vector<Mat3> frames;
    frames.reserve(3 * triangles.size());
    for (const auto& t : triangles) {
        const Vec3 n = (t[1] - t[0]).cross(t[2] - t[0]);
        if (!(n.norm() > tiny * std::sqrt(farthest))) continue;
        for (int e = 0; e < 3; ++e) {
            const Vec3 edge = t[static_cast<std::size_t>((e + 1) % 3)] - t[static_cast<std::size_t>(e)];
            if (!(edge.norm() > tiny)) continue;
            Mat3 axes;
            axes.col(0) = edge;
            axes.col(1) = n;
            axes.col(2) = Vec3::Zero();
            frames.push_back(proper_frame(axes));
        }
    }
    return frames;
}

void hull_outline(const SphereProxy& proxy, const Mat3& basis, const Vec3& origin, std::vector<Eigen::Vector2d>& hull,
                  OutlineScratch& scratch) {
    const auto project = [&](const Vec3& p) {
        const Vec3 d = p - origin;
        return Eigen::Vector2d(d.dot(basis.col(1)), d.dot(basis.col(2)));
    };
    if (outline_along(proxy.surface, basis.col(0), scratch) && scratch.outline.size() <= calipers_above) {
        hull.clear();
        for (std::uint32_t slot : scratch.outline) hull.push_back(project(proxy.hull_points[slot]));
        return;
    }
    std::vector<Eigen::Vector2d>& projected = scratch.projected;
    // Every centre lies in the hull of the hull-vertex centres, so their projections span the same 2-D hull:
    // sorting only those keeps this O(hull size) per call even when many spheres are kept.
    projected.clear();
    for (const Vec3& p : proxy.hull_points) projected.push_back(project(p));
    hull_2d(projected, hull);
}

SphereProxy make_proxy(std::span<const Sphere> spheres, const HullSummary& hull) {
    SphereProxy proxy;
    proxy.surface = hull.surface;
    thread_local std::vector<bool> taken;  // per thread and kept (memory/thread_scratch.hpp)
    const ReleaseIfLarge release(taken);
    taken.assign(spheres.size(), false);
    proxy.hull_points.reserve(hull.vertices.size());
    proxy.spheres.reserve(spheres.size());
    for (std::uint32_t i : hull.vertices) {
        taken[i] = true;
        proxy.hull_points.push_back(spheres[i].center);
    }
    for (std::size_t i = 0; i < spheres.size(); ++i) {
        if (taken[i] || spheres[i].radius > 0.0) proxy.spheres.push_back(spheres[i]);
        proxy.max_radius = std::max(proxy.max_radius, spheres[i].radius);
    }
    return proxy;
}

std::vector<Mat3> select_hints(const SphereProxy& proxy, std::span<const Mat3> hints, std::size_t limit) {
    std::vector<Mat3> frames;
    frames.reserve(hints.size());
    for (const Mat3& axes : hints) frames.push_back(proper_frame(axes));
    if (frames.size() <= limit) return frames;
    std::vector<std::pair<double, std::size_t>> ranked;
    ranked.reserve(frames.size());
    for (std::size_t i = 0; i < frames.size(); ++i) {
        const Mat3 to_local = frames[i].transpose();
        Vec3 low = Vec3::Constant(infinity);
        Vec3 high = Vec3::Constant(-infinity);
        for (const Vec3& p : proxy.hull_points) {
            const Vec3 local = to_local * p;
            low = low.cwiseMin(local);
            high = high.cwiseMax(local);
        }
        ranked.emplace_back((high - low + Vec3::Constant(2.0 * proxy.max_radius)).prod(), i);
    }
    std::partial_sort(ranked.begin(), ranked.begin() + static_cast<std::ptrdiff_t>(limit), ranked.end());
    std::vector<Mat3> selected;
    selected.reserve(limit);
    for (std::size_t i = 0; i < limit; ++i) selected.push_back(frames[ranked[i].second]);
    return selected;
}

HBVH_WIDE_CLONES_INLINED std::vector<Mat3> face_flush_frames(const SphereProxy& proxy, std::span<const Vec3> normals) {
    std::vector<Mat3> frames;
    frames.reserve(normals.size());
    const double pad = 2.0 * proxy.max_radius;
    // Per thread and kept (memory/thread_scratch.hpp): fresh ones were five allocations and their growth per fit.
    thread_local OutlineScratch scratch;
    thread_local std::vector<Eigen::Vector2d> hull;
    thread_local std::vector<double> xs, ys;  // the hull's vertices in two arrays, for polygon_extent's lanes
    thread_local std::vector<EdgeExtremes> extremes;
    const ReleaseIfLarge release(hull, xs, ys, extremes, scratch);
    for (const Vec3& normal : normals) {
        const Mat3 basis = frame_from_axis(normal);
        hull_outline(proxy, basis, Vec3::Zero(), hull, scratch);
        // Try each hull edge as a rectangle side: over every vertex for small hulls (O(h^2), exact), by
        // rotating calipers above (O(h); a flat ring of 10^5 spheres projects to a 2-D hull of 10^5 points).
        const bool brute_force = hull.size() <= calipers_above;
        if (brute_force) {
            xs.clear(), ys.clear();
            for (const Eigen::Vector2d& q : hull) xs.push_back(q.x()), ys.push_back(q.y());
        } else {
            edge_extremes(hull, extremes);
        }
        Eigen::Vector2d best_direction(1.0, 0.0);
        double best_area = infinity;
        for (std::size_t i = 0; i < hull.size(); ++i) {
            const std::size_t next = (i + 1) % hull.size();
            const Eigen::Vector2d edge = hull[next] - hull[i];
            if (!(edge.norm() > 0.0)) continue;
            const Eigen::Vector2d d = edge.normalized();
            const Eigen::Vector2d perpendicular(-d.y(), d.x());
            double low_d = infinity, high_d = -infinity, low_p = infinity, high_p = -infinity;
            if (brute_force) {
                const PolygonExtent e = polygon_extent(xs, ys, d);
                low_d = e.low_along, high_d = e.high_along, low_p = e.low_across, high_p = e.high_across;
            } else {
                // Every vertex lies on the inner side of the edge's line, so the edge's ends are lowest across it.
                const EdgeExtremes& e = extremes[i];
                low_d = hull[e.lowest_along].dot(d), high_d = hull[e.highest_along].dot(d);
                low_p = std::min(hull[i].dot(perpendicular), hull[next].dot(perpendicular));
                high_p = hull[e.farthest_across].dot(perpendicular);
            }
            const double area = (high_d - low_d + pad) * (high_p - low_p + pad);
            if (area < best_area) best_area = area, best_direction = d;
        }
        Mat3 axes;
        axes.col(0) = basis.col(0);
        axes.col(1) = best_direction.x() * basis.col(1) + best_direction.y() * basis.col(2);
        axes.col(2) = Vec3::Zero();
        frames.push_back(proper_frame(axes));
    }
    return frames;
}

namespace {

/// The box with axes `rotation` whose local extent is [low, high], grown to every sphere's reach from its
/// centre (re-centring rounds), then padded for the rounding of the containment test's own arithmetic.
Obb finish_box(std::span<const Sphere> spheres, const Mat3& rotation, const Vec3& low, const Vec3& high) {
    Obb box{rotation * (0.5 * (low + high)), rotation, 0.5 * (high - low)};
    // Re-centring rounds; grow by what each sphere reaches from the new centre, as the containment test measures
    // it (up to the order of a sum, which the pad below covers).
    extend_half_extents(spheres, rotation, box.center, box.half_extents);
    // Local coordinates are differences of nearby points, so their rounding scales with the box, not
    // with its distance from the origin.
    box.half_extents.array() += rounding_pad(box.half_extents.maxCoeff());
    return box;
}

}  // namespace

Obb obb_with_axes(std::span<const Sphere> spheres, const Mat3& rotation) {
    const SphereExtents extents = sphere_extents(spheres, rotation);
    return finish_box(spheres, rotation, extents.low, extents.high);
}

std::optional<Obb> obb_with_axes_below(std::span<const Sphere> spheres, const Mat3& rotation, double limit) {
    // The extent only grows, and the finished box only grows it further: once this product reaches the limit
    // after a block of spheres, the box cannot end below it.
    constexpr std::size_t block = 8;
    SphereExtents extents;
    for (std::size_t i = 0; i < spheres.size(); i += block) {
        extend_extents(spheres.subspan(i, std::min(block, spheres.size() - i)), rotation, extents);
        if ((extents.high - extents.low).prod() >= limit) return std::nullopt;
    }
    if ((extents.high - extents.low).prod() >= limit) return std::nullopt;
    return finish_box(spheres, rotation, extents.low, extents.high);
}

double proxy_obb_volume(const SphereProxy& proxy, const Mat3& rotation) {
    const SphereExtents extents = sphere_extents(proxy.spheres, rotation);
    return (extents.high - extents.low).prod();
}

namespace {

// refine_frame's pattern search: the first step (about 6 degrees), the last one it takes (about 0.01 degree,
// each step half the one before), and the most candidate frames it ranks.
constexpr double first_refine_step = 0.1;
constexpr double least_refine_step = 2e-4;
constexpr int max_refine_evaluations = 180;

/// How many steps, halving from `first`, stay above `least` (9 for 0.1 and 2e-4: the last is 3.9e-4).
constexpr std::size_t halvings_above(double first, double least) {
    std::size_t count = 0;
    for (double step = first; step > least; step *= 0.5) ++count;
    return count;
}
constexpr std::size_t refine_step_count = halvings_above(first_refine_step, least_refine_step);

/// The search's rotations, about each axis by + and - each step: made once, the same matrices as made per
/// candidate before (a sine and a cosine each, 2 % of an `auto` build's instructions).
struct RefineRotations {
    std::array<std::array<std::array<Mat3, 2>, 3>, refine_step_count> by_step;  // [step][axis][sign: +, -]
    RefineRotations() {
        double step = first_refine_step;
        for (auto& by_axis : by_step) {
            for (int axis = 0; axis < 3; ++axis)
                for (int s = 0; s < 2; ++s)
                    by_axis[static_cast<std::size_t>(axis)][static_cast<std::size_t>(s)] =
                        Eigen::AngleAxisd((s == 0 ? 1.0 : -1.0) * step, Vec3::Unit(axis)).toRotationMatrix();
            step *= 0.5;
        }
    }
};

}  // namespace

Mat3 refine_frame(const SphereProxy& proxy, const Mat3& rotation) {
    // Pattern search: try +-step about each box axis, keep any improvement, halve the step when none
    // helps. Start at ~6 degrees (candidate frames are usually close) and stop below ~0.01 degree.
    static const RefineRotations rotations;
    Mat3 best = rotation;
    double best_volume = proxy_obb_volume(proxy, best);
    std::size_t step = 0;
    int evaluations = 0;
    while (step < refine_step_count && evaluations < max_refine_evaluations) {
        bool improved = false;
        for (std::size_t axis = 0; axis < 3 && evaluations < max_refine_evaluations; ++axis)
            for (const Mat3& turn : rotations.by_step[step][axis]) {
                const Mat3 candidate = best * turn;
                const double v = proxy_obb_volume(proxy, candidate);
                ++evaluations;
                if (v < best_volume * (1.0 - 1e-12)) {
                    best = candidate;
                    best_volume = v;
                    improved = true;
                }
            }
        if (!improved) ++step;
    }
    return proper_frame(best);
}

}  // namespace hbvh::detail
