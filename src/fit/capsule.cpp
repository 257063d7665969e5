// SPDX-License-Identifier: MIT
// fit_capsule: for each candidate axis direction the smallest capsule along it, then the best of them.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <utility>
#include <vector>

#include "convex_hull.hpp"
#include "fit_context.hpp"
#include "frames.hpp"
#include "hbvh/assert.hpp"
#include "hbvh/fit/fit.hpp"
#include "capsule_segment.hpp"
#include "min_circle.hpp"

namespace hbvh {
namespace {

using detail::AxisDistances;
using detail::keep_end_candidates;
using detail::segment_for_radius;

/// The spheres in a frame whose column 0 is the capsule axis: axial coordinate and 2-D cross-section.
struct Projected {
    std::vector<double> axial;
    std::vector<detail::Circle> section;
};

/// Fills `p` (cleared first; its storage is reused across the fitter's ~100 directions).
void project(std::span<const Sphere> spheres, const Mat3& frame, Projected& p) {
    p.axial.clear();
    p.section.clear();
    for (const Sphere& s : spheres) {
        const Vec3 local = frame.transpose() * s.center;
        p.axial.push_back(local.x());
        p.section.push_back({Eigen::Vector2d(local.y(), local.z()), s.radius});
    }
}

double capsule_volume(double radius, double length) {
    return std::numbers::pi * radius * radius * length + 4.0 / 3.0 * std::numbers::pi * radius * radius * radius;
}

/// The buffers capsule_along fills, kept by the caller so that one fit allocates them once, not once per
/// direction (allocation was a tenth of the capsule fitter's time).
struct CapsuleScratch {
    Projected projected;
    AxisDistances distances;
    AxisDistances bracket;  ///< The spheres that can set an end inside the golden-section bracket.
};

/// A capsule along column 0 of `frame` (a proper rotation) around `spheres`.
/// exact_line: place the axis at the centre of the minimum enclosing circle of the cross-sections (the
/// smallest possible radius) and search for a larger radius that shortens the capsule enough to pay off;
/// otherwise use the cross-sections' bounding-rectangle centre and the smallest radius, a cheap
/// estimate for ranking directions.
Capsule capsule_along(std::span<const Sphere> spheres, const Mat3& frame, bool exact_line, CapsuleScratch& scratch) {
    Projected& p = scratch.projected;
    project(spheres, frame, p);
    Eigen::Vector2d line = Eigen::Vector2d::Zero();
    if (exact_line) {
        line = detail::min_circle_of_circles(p.section).center;
    } else {
        Eigen::Vector2d low = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
        Eigen::Vector2d high = -low;
        for (const detail::Circle& c : p.section) {
            low = low.cwiseMin(c.center - Eigen::Vector2d::Constant(c.radius));
            high = high.cwiseMax(c.center + Eigen::Vector2d::Constant(c.radius));
        }
        line = 0.5 * (low + high);
    }
    AxisDistances& distances = scratch.distances;
    distances.axial = p.axial;
    distances.radius.resize(p.section.size());
    distances.distance_squared.resize(p.section.size());
    double min_radius = 0.0;
    for (std::size_t i = 0; i < p.section.size(); ++i) {
        const double distance = (p.section[i].center - line).norm();
        distances.radius[i] = p.section[i].radius;
        distances.distance_squared[i] = distance * distance;
        min_radius = std::max(min_radius, distance + p.section[i].radius);
    }

    auto volume_at = [](const AxisDistances& candidates, double r) {
        const auto [t0, t1] = segment_for_radius(candidates, r);
        return capsule_volume(r, t1 - t0);
    };
    double radius = min_radius;
    const auto [first_t0, first_t1] = segment_for_radius(distances, min_radius);
    const double first_length = first_t1 - first_t0;
    const AxisDistances* final_set = &distances;
    if (exact_line && first_length > 0.0) {
        // A fatter capsule can be shorter: the end caps then swallow spheres near the ends. Sample radii
        // geometrically up to one length more, then golden-section search around the best sample. The search
        // reads only the spheres that can set an end within its bracket (the same segments, bit for bit); over
        // the samples' wide range nearly every sphere can, so they read all.
        std::array<double, 8> radii{min_radius};
        std::size_t sampled = 1;
        for (double g = 1.0 / 64.0; g <= 1.0; g *= 2.0) radii[sampled++] = min_radius + g * first_length;
        std::size_t best = 0;
        double best_volume = volume_at(distances, radii[0]);
        for (std::size_t i = 1; i < sampled; ++i) {
            const double v = volume_at(distances, radii[i]);
            if (v < best_volume) best = i, best_volume = v;
        }
        double a = radii[best == 0 ? 0 : best - 1];
        double b = radii[std::min(best + 1, sampled - 1)];
        radius = radii[best];
        keep_end_candidates(distances, a, b, scratch.bracket);
        const AxisDistances& bracket = scratch.bracket;
        const double ratio = (std::sqrt(5.0) - 1.0) / 2.0;
        double x1 = b - ratio * (b - a);
        double x2 = a + ratio * (b - a);
        double f1 = volume_at(bracket, x1);
        double f2 = volume_at(bracket, x2);
        // 16 steps shrink the bracket to 5e-4 of its width; near the optimum the volume is flat (quadratic),
        // so the remaining error is far below anything a builder could notice.
        for (int iteration = 0; iteration < 16; ++iteration) {
            if (f1 < f2) {
                b = x2, x2 = x1, f2 = f1;
                x1 = b - ratio * (b - a), f1 = volume_at(bracket, x1);
            } else {
                a = x1, x1 = x2, f1 = f2;
                x2 = a + ratio * (b - a), f2 = volume_at(bracket, x2);
            }
        }
        for (const auto& [x, f] : {std::pair{x1, f1}, std::pair{x2, f2}})
            if (f < best_volume) radius = x, best_volume = f;
        final_set = &bracket;  // radius lies in the bracket: radii[best], x1 or x2
    }

    const auto [t0, t1] = segment_for_radius(*final_set, radius);
    const Vec3 axis = frame.col(0);
    const Vec3 base = frame.col(1) * line.x() + frame.col(2) * line.y();
    return {base + t0 * axis, base + t1 * axis, radius};
}

/// Grows the radius until Capsule::contains holds for every sphere with zero tolerance: the segment
/// ends were rounded when mapped back to world coordinates.
void make_containing(Capsule& capsule, std::span<const Sphere> spheres) {
    double magnitude = capsule.radius;
    for (const Sphere& s : spheres) {
        capsule.radius = std::max(capsule.radius, (s.center - capsule.closest_axis_point(s.center)).norm() + s.radius);
        magnitude = std::max(magnitude, s.center.cwiseAbs().maxCoeff());
    }
    // World coordinates round with their magnitude; a few ulps of it cover a re-evaluation that rounds
    // differently (fused multiply-add).
    capsule.radius += magnitude * 0x1.0p-51;
}

}  // namespace

Capsule fit_capsule(std::span<const Sphere> spheres, std::span<const Mat3> hint_axes) {
    HBVH_ASSERT(!spheres.empty());
    return detail::fit_capsule_in(detail::make_fit_context(spheres, hint_axes), spheres, fit_sphere(spheres));
}

Capsule detail::fit_capsule_in(const FitContext& context, std::span<const Sphere> spheres, const Sphere& sphere) {
    const detail::HullSummary& hull = context.hull;

    // Stage 1: candidate directions. The principal axes of the centres and of the hull, every axis of the
    // OBB candidate frames (world, DiTO, hints): a capsule's axis usually follows the longest box side.
    const detail::SphereProxy& proxy = context.proxy;
    const Mat3 point_frame = detail::principal_frame(detail::point_covariance(spheres));
    std::vector<Mat3> frames{point_frame, detail::principal_frame(hull.covariance), Mat3::Identity()};
    for (const Mat3& axes : context.dito) frames.push_back(axes);
    for (const Mat3& axes : context.hints) frames.push_back(axes);
    std::vector<Vec3> directions;
    directions.reserve(3 * frames.size());
    for (const Mat3& frame : frames)
        for (int k = 0; k < 3; ++k) directions.push_back(frame.col(k));

    // Stage 2: rank directions by a cheap capsule (axis through the centre of the cross-sections' bounding
    // rectangle) around the proxy: hull vertices and spheres of positive radius.
    CapsuleScratch scratch;
    std::vector<std::pair<double, std::size_t>> ranked;
    ranked.reserve(directions.size());
    for (std::size_t i = 0; i < directions.size(); ++i)
        ranked.emplace_back(capsule_along(proxy.spheres, detail::frame_from_axis(directions[i]), false, scratch).volume(), i);
    const std::size_t keep = std::min<std::size_t>(3, ranked.size());
    std::partial_sort(ranked.begin(), ranked.begin() + static_cast<std::ptrdiff_t>(keep), ranked.end());

    // Stage 3: full capsules (minimum enclosing circle, radius search) for the principal axis of the
    // centres and the best-ranked directions. The proxy gives the same capsule as the whole set (the
    // dropped points lie in the hull of the kept ones), for less work.
    std::span<const Sphere> kept = proxy.spheres;
    Vec3 best_direction = point_frame.col(0);
    Capsule best = capsule_along(kept, detail::frame_from_axis(best_direction), true, scratch);
    for (std::size_t i = 0; i < keep; ++i) {
        const Vec3& direction = directions[ranked[i].second];
        Capsule candidate = capsule_along(kept, detail::frame_from_axis(direction), true, scratch);
        if (candidate.volume() < best.volume()) best = candidate, best_direction = direction;
    }

    // Stage 4: polish the winning direction by tilting it about two perpendicular axes (pattern search
    // with halving step, as for the OBB frame), evaluating full capsules.
    double step = 0.05;
    int evaluations = 0;
    while (step > 1e-3 && evaluations < 32) {
        bool improved = false;
        const Mat3 frame = detail::frame_from_axis(best_direction);
        for (int axis = 1; axis <= 2; ++axis)
            for (double sign : {1.0, -1.0}) {
                const Vec3 direction = Eigen::AngleAxisd(sign * step, frame.col(axis)) * best_direction;
                Capsule candidate = capsule_along(kept, detail::frame_from_axis(direction), true, scratch);
                ++evaluations;
                if (candidate.volume() < best.volume() * (1.0 - 1e-12))
                    best = candidate, best_direction = direction, improved = true;
            }
        if (!improved) step *= 0.5;
    }

    // The minimum enclosing sphere is a capsule of length zero; with it as a candidate a capsule is never
    // worse than the sphere fitter.
    if (sphere.volume() < best.volume()) best = Capsule{sphere.center, sphere.center, sphere.radius};
    make_containing(best, spheres);
    return best;
}

}  // namespace hbvh
