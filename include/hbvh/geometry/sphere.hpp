// SPDX-License-Identifier: MIT
// Sphere: a centre and a radius. Radius 0 is a point, the building block of every fitter.
#pragma once

#include <numbers>

#include "hbvh/geometry/vector.hpp"

namespace hbvh {

/// A ball in world space. radius >= 0.
struct Sphere {
    Vec3 center = Vec3::Zero();
    double radius = 0.0;

    [[nodiscard]] double volume() const { return 4.0 / 3.0 * std::numbers::pi * radius * radius * radius; }
    /// True when every point of `other` lies inside this sphere, allowing `tolerance` (absolute length).
    [[nodiscard]] bool contains(const Sphere& other, double tolerance = 0.0) const {
        return (other.center - center).norm() + other.radius <= radius + tolerance;
    }
    [[nodiscard]] Sphere transformed(const RigidTransform& t) const { return {t.apply(center), radius}; }
};

}  // namespace hbvh
