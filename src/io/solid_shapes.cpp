// SPDX-License-Identifier: MIT
// Cylinder and ellipsoid enclosures: the closed forms behind the importers' OBB-or-capsule rule.
#include "hbvh/io/solid_shapes.hpp"

#include <cmath>

#include "hbvh/assert.hpp"

namespace hbvh {
namespace {

Capsule capsule_along_z(const RigidTransform& frame, double radius, double half_length) {
    const Vec3 axis = frame.rotation.col(2);
    return {frame.translation - half_length * axis, frame.translation + half_length * axis, radius};
}

}  // namespace

Capsule enclosing_capsule_of_cylinder(const RigidTransform& frame, double radius, double half_length) {
    HBVH_ASSERT(radius > 0.0 && half_length >= 0.0);
    // Shorten the segment by t and grow the radius to reach the rim: R^2 = r^2 + t^2, L = h - t.
    // V(t) = 2 pi R^2 (h - t) + 4/3 pi R^3 is unimodal on [0, h] (checked numerically for h/r in (0, 20]), and
    // V'(t) / 2pi = g(t) = 2t(h - t) - (r^2 + t^2) + 2t R, with g(0) = -r^2 < 0: keeping the cylinder's own radius
    // is never optimal. Bisect on the sign of g; when g(h) <= 0 the best capsule is the circumscribed sphere.
    const double r = radius;
    const double h = half_length;
    auto slope = [&](double t) { return 2.0 * t * (h - t) - (r * r + t * t) + 2.0 * t * std::sqrt(r * r + t * t); };
    double t = h;
    if (slope(h) > 0.0) {
        double lo = 0.0;
        double hi = h;
        for (int iteration = 0; iteration < 200 && hi - lo > 0.0; ++iteration) {
            const double mid = 0.5 * (lo + hi);
            if (mid <= lo || mid >= hi) break;
            (slope(mid) > 0.0 ? hi : lo) = mid;
        }
        t = 0.5 * (lo + hi);
    }
    return capsule_along_z(frame, std::sqrt(r * r + t * t), h - t);
}

BoundingVolume enclose_cylinder(const RigidTransform& frame, double radius, double half_length) {
    const Obb box{frame.translation, frame.rotation, Vec3(radius, radius, half_length)};
    const Capsule capsule = enclosing_capsule_of_cylinder(frame, radius, half_length);
    if (capsule.volume() < box.volume()) return capsule;
    return box;
}

Capsule enclosing_capsule_of_ellipsoid(const RigidTransform& frame, const Vec3& semi_axes) {
    HBVH_ASSERT((semi_axes.array() > 0.0).all());
    // Put the capsule axis on the longest semi-axis c. With m the larger of the other two, the farthest surface
    // point from a segment of half-length L is at distance max(m, c - L), so R = m, L = c - m is optimal (a longer
    // radius only trades cylinder volume for more cap volume). Axis order is kept for ties so results are stable.
    int longest = 2;
    for (int axis = 1; axis >= 0; --axis)
        if (semi_axes[axis] > semi_axes[longest]) longest = axis;
    double middle = 0.0;
    for (int axis = 0; axis < 3; ++axis)
        if (axis != longest) middle = std::max(middle, semi_axes[axis]);
    const Vec3 direction = frame.rotation.col(longest);
    const double half_length = semi_axes[longest] - middle;
    return {frame.translation - half_length * direction, frame.translation + half_length * direction, middle};
}

BoundingVolume enclose_ellipsoid(const RigidTransform& frame, const Vec3& semi_axes) {
    const Obb box{frame.translation, frame.rotation, semi_axes};
    const Capsule capsule = enclosing_capsule_of_ellipsoid(frame, semi_axes);
    if (capsule.volume() < box.volume()) return capsule;
    return box;
}

}  // namespace hbvh
