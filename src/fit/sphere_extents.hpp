// SPDX-License-Identifier: MIT
// Internal: how far a set of spheres reaches along the axes of a frame or around a line, the inner loops of the
// box and capsule fits.
#pragma once

#include <limits>
#include <span>

#include "hbvh/geometry/sphere.hpp"

namespace hbvh::detail {

/// Along each axis of a frame, the least and the greatest coordinate of the spheres' surfaces.
struct SphereExtents {
    Vec3 low = Vec3::Constant(std::numeric_limits<double>::infinity());
    Vec3 high = Vec3::Constant(-std::numeric_limits<double>::infinity());
};

/// Folds `spheres` into `extents` along the columns of `frame` (any matrix; for a rotation, the extents of
/// the box with those axes around the spheres, in the frame's coordinates). A centre's coordinate along
/// axis i is (c.x frame(0, i) + c.y frame(1, i)) + c.z frame(2, i), in that order on every axis and in either
/// of the function's two compiled copies (simd/wide_clones.hpp), so the result does not depend on the machine.
void extend_extents(std::span<const Sphere> spheres, const Mat3& frame, SphereExtents& extents);

/// Grows `half_extents` to each sphere's reach from `center` along the columns of `frame`: per axis i, the
/// largest |d . frame.col(i)| + radius, d = c - center, the dot product formed as extend_extents forms it. The
/// box fits' last pass (a box with those axes, centred there, then holds every sphere up to rounding, which
/// their pad covers).
void extend_half_extents(std::span<const Sphere> spheres, const Mat3& frame, const Vec3& center, Vec3& half_extents);

/// How far `spheres` reach around the line through `origin` along unit `axis`: the largest distance of a sphere's
/// surface from the line, and the least and greatest position of a centre along it. With d = c - origin, a
/// centre's position is t = (d.x a.x + d.y a.y) + d.z a.z, and its distance sqrt((e.x^2 + e.y^2) + e.z^2) for
/// e = d - t a, in that order in both compiled copies. The capsule on that line over [t_min, t_max] with that
/// radius holds every sphere (up to rounding, which the callers pad).
struct LineReach {
    double radius = 0.0;
    double t_min = std::numeric_limits<double>::infinity();
    double t_max = -std::numeric_limits<double>::infinity();
};
[[nodiscard]] LineReach line_reach(std::span<const Sphere> spheres, const Vec3& origin, const Vec3& axis);

/// The extents of `spheres` along the columns of `frame` (empty extents for no spheres).
[[nodiscard]] inline SphereExtents sphere_extents(std::span<const Sphere> spheres, const Mat3& frame) {
    SphereExtents extents;
    extend_extents(spheres, frame, extents);
    return extents;
}

}  // namespace hbvh::detail
