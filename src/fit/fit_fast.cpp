// SPDX-License-Identifier: MIT
// fit_fast: the scale builder's enclosing fitter for big groups, linear in the number of spheres.
//
// fit_best's OBB and capsule fitters build a convex hull and try dozens of frames (about a millisecond
// per call); a level of 10^6 nodes cannot afford that per candidate. Boxes and capsules in a handful of
// frames that the data suggests (world, principal axes, the children's own frames) are a few passes over
// the spheres, and they still enclose every sphere exactly.
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>

#include "frames.hpp"
#include "rounding_pad.hpp"
#include "sphere_extents.hpp"
#include "hbvh/assert.hpp"
#include "hbvh/fit/fit_fast.hpp"
#include "hbvh/fit/fit.hpp"

namespace hbvh {
namespace {

/// The capsule on the line through `origin` along unit `axis` whose radius covers every sphere's distance
/// from the line and whose segment spans the centres' projections, so every sphere is inside.
Capsule capsule_on(std::span<const Sphere> spheres, const Vec3& origin, const Vec3& axis) {
    const detail::LineReach reach = detail::line_reach(spheres, origin, axis);
    // A few ulps of slack: Capsule::contains measures the distance through the clamped segment point,
    // which rounds differently from the line distance above.
    const double radius = reach.radius + reach.radius * 0x1.0p-48;
    return Capsule{origin + reach.t_min * axis, origin + reach.t_max * axis, radius};
}

/// A sphere around `spheres` centred at the better of two cheap centres (world-box centre, mean centre):
/// at most a few tens of percent larger than the minimum one, at a fraction of its cost.
Sphere quick_sphere(std::span<const Sphere> spheres, const Vec3& mean) {
    const Vec3 box_centre = fit_aabb(spheres).center();
    Sphere best{box_centre, std::numeric_limits<double>::infinity()};
    for (const Vec3& centre : {box_centre, mean}) {
        double radius = 0.0;
        for (const Sphere& s : spheres) radius = std::max(radius, (s.center - centre).norm() + s.radius);
        radius += radius * 0x1.0p-48;  // containment re-evaluated with other rounding must still hold
        if (radius < best.radius) best = {centre, radius};
    }
    return best;
}

}  // namespace

BoundingVolume fit_fast(std::span<const Sphere> spheres, std::span<const BoundingVolume> hints,
                        const VolumePolicy& policy) {
    return fit_fast(spheres, hints, policy, FastFitMode::exact_sphere);
}

BoundingVolume fit_fast(std::span<const Sphere> spheres, std::span<const BoundingVolume> hints,
                        const VolumePolicy& policy, FastFitMode mode) {
    HBVH_ASSERT(!spheres.empty());
    std::optional<BoundingVolume> best;
    double best_cost = std::numeric_limits<double>::infinity();
    // Strict '<' keeps the earlier kind on ties, in fit_best's order (AABB, OBB, sphere, capsule).
    const auto consider = [&](BoundingVolume candidate) {
        const double c = policy.weighted_volume(candidate);
        if (!best || c < best_cost) {
            best = std::move(candidate);
            best_cost = c;
        }
    };
    // With volume as the measure, a candidate that cannot beat the best so far is not finished (the result is
    // the same: only losers are skipped). `within` is the largest unweighted volume a kind could still win with,
    // a hair above the exact figure so that rounding in a bound never skips a winner.
    const bool prune = policy.measure == NodeMeasure::volume;
    const auto within = [&](BvType type) {
        const double weight = policy.weight_of(type);
        return best && prune && weight > 0.0 ? best_cost / weight * (1.0 + 1e-9)
                                             : std::numeric_limits<double>::infinity();
    };
    const Aabb world_box = fit_aabb(spheres);
    if (policy.is_allowed(BvType::aabb)) consider(world_box);

    const bool want_obb = policy.is_allowed(BvType::obb);
    const bool want_capsule = policy.is_allowed(BvType::capsule);
    Vec3 mean = Vec3::Zero();
    Mat3 principal = Mat3::Identity();
    const bool want_sphere = policy.is_allowed(BvType::sphere);
    if (want_obb || want_capsule || (want_sphere && mode == FastFitMode::quick_sphere)) {
        // Principal axes of the centres, as Gottschalk's covariance fit but without the hull.
        for (const Sphere& s : spheres) mean += s.center;
        mean /= static_cast<double>(spheres.size());
    }
    if (want_obb || want_capsule) {
        Mat3 covariance = Mat3::Zero();
        for (const Sphere& s : spheres) covariance += (s.center - mean) * (s.center - mean).transpose();
        principal = detail::principal_frame(covariance);
    }
    if (want_obb) {
        // A box's volume is at least the product of its extents along its axes, which obb_with_axes_below
        // measures before finishing it (finishing only grows it).
        const auto consider_box = [&](const Mat3& rotation) {
            if (std::optional<Obb> box = detail::obb_with_axes_below(spheres, rotation, within(BvType::obb)))
                consider(std::move(*box));
        };
        consider_box(Mat3::Identity());
        consider_box(principal);
        for (const BoundingVolume& hint : hints)
            if (const Obb* box = std::get_if<Obb>(&hint)) consider_box(box->rotation);
    }
    if (want_sphere) {
        // Any sphere around the set is at least as wide as the set along each world axis (fit_aabb's rounding
        // pads, about 4 ulps of the coordinates at each end, taken off twice over).
        double widest = 0.0;
        for (int axis = 0; axis < 3; ++axis) {
            const double magnitude = std::max(std::abs(world_box.min[axis]), std::abs(world_box.max[axis]));
            widest = std::max(widest, world_box.max[axis] - world_box.min[axis] - 4.0 * detail::rounding_pad(magnitude));
        }
        const double smallest_sphere = 4.0 / 3.0 * std::numbers::pi * std::pow(0.5 * widest, 3);
        if (smallest_sphere < within(BvType::sphere))
            consider(mode == FastFitMode::exact_sphere ? fit_sphere(spheres) : quick_sphere(spheres, mean));
    }
    if (want_capsule) {
        consider(capsule_on(spheres, mean, principal.col(0)));
        for (const BoundingVolume& hint : hints)
            if (const Capsule* capsule = std::get_if<Capsule>(&hint))
                if (capsule->length() > 0.0) consider(capsule_on(spheres, capsule->center(), capsule->direction()));
    }
    HBVH_ASSERT(best.has_value());
    return *best;
}

}  // namespace hbvh
