// SPDX-License-Identifier: MIT
// Capsule: the points within `radius` of the segment [p0, p1] (a swept sphere).
#pragma once

#include <algorithm>
#include <numbers>

#include "hbvh/geometry/sphere.hpp"

namespace hbvh {

/// Capsule in world space: all points at distance <= radius from the segment p0-p1.
struct Capsule {
    Vec3 p0 = Vec3::Zero();
    Vec3 p1 = Vec3::Zero();
    double radius = 0.0;

    [[nodiscard]] Vec3 center() const { return 0.5 * (p0 + p1); }
    /// Distance between the two end-sphere centres (the survey's `length`).
    [[nodiscard]] double length() const { return (p1 - p0).norm(); }
    /// Unit axis p0 -> p1; +z for a degenerate (spherical) capsule.
    [[nodiscard]] Vec3 direction() const {
        const Vec3 d = p1 - p0;
        const double n = d.norm();
        return n > 0.0 ? Vec3(d / n) : Vec3::UnitZ();
    }
    /// pi r^2 L + 4/3 pi r^3.
    [[nodiscard]] double volume() const {
        return std::numbers::pi * radius * radius * length() + 4.0 / 3.0 * std::numbers::pi * radius * radius * radius;
    }
    /// Closest point of the axis segment to `point`.
    [[nodiscard]] Vec3 closest_axis_point(const Vec3& point) const {
        const Vec3 d = p1 - p0;
        const double dd = d.squaredNorm();
        if (dd <= 0.0) return p0;
        const double t = std::clamp((point - p0).dot(d) / dd, 0.0, 1.0);
        return p0 + t * d;
    }
    /// True when every point of `s` is inside, allowing `tolerance` (absolute length).
    [[nodiscard]] bool contains(const Sphere& s, double tolerance = 0.0) const {
        return (s.center - closest_axis_point(s.center)).norm() + s.radius <= radius + tolerance;
    }
    [[nodiscard]] Capsule transformed(const RigidTransform& t) const { return {t.apply(p0), t.apply(p1), radius}; }
};

}  // namespace hbvh
