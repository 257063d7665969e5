// SPDX-License-Identifier: MIT
// fit_fast: the scale builder's enclosing fitter for big groups, linear in the number of spheres.
//
// fit_best's OBB and capsule fitters build a convex hull and try dozens of frames (about a millisecond
// per call); a level of 10^6 nodes cannot afford that per candidate. Boxes and capsules in a handful of
// frames that the data suggests (world, principal axes, the children's own frames) are a few passes over
// the spheres, and they still enclose every sphere exactly.
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <limits>
#include <optional>

#include "frames.hpp"
#include "hbvh/assert.hpp"
#include "hbvh/fit/fit_fast.hpp"
#include "hbvh/fit/fit.hpp"

namespace hbvh {
namespace {

/// The capsule on the line through `origin` along unit `axis` whose radius covers every sphere's distance
/// from the line and whose segment spans the centres' projections, so every sphere is inside.
Capsule capsule_on(std::span<const Sphere> spheres, const Vec3& origin, const Vec3& axis) {
    double radius = 0.0;
    double t_min = std::numeric_limits<double>::infinity();
    double t_max = -t_min;
    for (const Sphere& s : spheres) {
        const Vec3 d = s.center - origin;
        const double t = d.dot(axis);
        radius = std::max(radius, (d - t * axis).norm() + s.radius);
        t_min = std::min(t_min, t);
        t_max = std::max(t_max, t);
    }
    // A few ulps of slack: Capsule::contains measures the distance through the clamped segment point,
    // which rounds differently from the line distance above.
    radius += radius * 0x1.0p-48;
    return Capsule{origin + t_min * axis, origin + t_max * axis, radius};
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
    if (policy.is_allowed(BvType::aabb)) consider(fit_aabb(spheres));

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
        consider(detail::obb_with_axes(spheres, Mat3::Identity()));
        consider(detail::obb_with_axes(spheres, principal));
        for (const BoundingVolume& hint : hints)
            if (const Obb* box = std::get_if<Obb>(&hint)) consider(detail::obb_with_axes(spheres, box->rotation));
    }
    if (want_sphere) consider(mode == FastFitMode::exact_sphere ? fit_sphere(spheres) : quick_sphere(spheres, mean));
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
