// SPDX-License-Identifier: MIT
// Internal: the minimum enclosing circle of circles, implemented next to fit_sphere (both use CGAL).
#pragma once

#include <span>

#include <Eigen/Core>

namespace hbvh::detail {

/// A circle in a plane's own 2-D coordinates.
struct Circle {
    Eigen::Vector2d center = Eigen::Vector2d::Zero();
    double radius = 0.0;
};

/// Smallest circle containing every input circle (centre, radius >= 0). Containment holds exactly when
/// measured as (c - center).norm() + r <= radius. Precondition: circles non-empty.
[[nodiscard]] Circle min_circle_of_circles(std::span<const Circle> circles);

}  // namespace hbvh::detail
