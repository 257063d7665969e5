// SPDX-License-Identifier: MIT
// Tight bounding volumes for the solid shapes robot formats have but hbvh does not: cylinders and ellipsoids.
#pragma once

#include "hbvh/geometry/bounding_volume.hpp"

namespace hbvh {

/// The smallest-volume capsule around a cylinder (radius r, half-length h along the local z axis of `frame`)
/// among capsules sharing its axis: radius sqrt(r^2 + t^2) and half-length h - t, with t >= 0 minimising the
/// volume. Precondition: r > 0, h >= 0.
[[nodiscard]] Capsule enclosing_capsule_of_cylinder(const RigidTransform& frame, double radius, double half_length);

/// A cylinder (radius r, half-length h along local z of `frame`) as the enclosing Obb (half extents r, r, h) or
/// the enclosing capsule of enclosing_capsule_of_cylinder, whichever has the smaller volume (Obb on ties).
/// Flat cylinders (discs, studs) become boxes; long ones (h above about 2r) become capsules.
[[nodiscard]] BoundingVolume enclose_cylinder(const RigidTransform& frame, double radius, double half_length);

/// The smallest capsule around an ellipsoid with semi-axes `semi_axes` along the local axes of `frame`: its axis is
/// the longest semi-axis c, its radius the middle one m and its half-length c - m (proof in docs/importers.md).
/// Precondition: semi_axes positive.
[[nodiscard]] Capsule enclosing_capsule_of_ellipsoid(const RigidTransform& frame, const Vec3& semi_axes);

/// An ellipsoid as the enclosing Obb (half extents = semi-axes, exact box) or enclosing_capsule_of_ellipsoid,
/// whichever has the smaller volume (Obb on ties).
[[nodiscard]] BoundingVolume enclose_ellipsoid(const RigidTransform& frame, const Vec3& semi_axes);

}  // namespace hbvh
