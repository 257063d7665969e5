// SPDX-License-Identifier: MIT
// Aabb: an axis-aligned box given by its two extreme corners.
#pragma once

#include "hbvh/geometry/sphere.hpp"

namespace hbvh {

/// Axis-aligned box in world space. min <= max componentwise; min == max on an axis is a flat box.
struct Aabb {
    Vec3 min = Vec3::Zero();
    Vec3 max = Vec3::Zero();

    [[nodiscard]] Vec3 center() const { return 0.5 * (min + max); }
    [[nodiscard]] Vec3 half_extents() const { return 0.5 * (max - min); }
    [[nodiscard]] double volume() const { return (max - min).prod(); }
    /// True when every point of `s` is inside, allowing `tolerance` (absolute length).
    [[nodiscard]] bool contains(const Sphere& s, double tolerance = 0.0) const {
        const Vec3 r = Vec3::Constant(s.radius - tolerance);
        return ((s.center - r).array() >= min.array()).all() && ((s.center + r).array() <= max.array()).all();
    }
    /// The smallest box containing both.
    [[nodiscard]] Aabb merged(const Aabb& other) const { return {min.cwiseMin(other.min), max.cwiseMax(other.max)}; }
    /// An empty box that any merge replaces.
    [[nodiscard]] static Aabb empty() { return {Vec3::Constant(1e300), Vec3::Constant(-1e300)}; }
};

}  // namespace hbvh
