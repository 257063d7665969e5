// SPDX-License-Identifier: MIT
// The survey XML stores an AABB as a centre and extents and a capsule as a centre, a direction and a length, while
// the library keeps corners and end points. These are the reader's conversions, and the writer's choice of fields
// that the reader turns back into exactly the same doubles.
#pragma once

#include "hbvh/geometry/aabb.hpp"
#include "hbvh/geometry/capsule.hpp"

namespace hbvh::detail {

/// The box the reader makes of `pos` and the extents (width, depth, height).
[[nodiscard]] inline Aabb aabb_from_fields(const Vec3& centre, const Vec3& extents) {
    const Vec3 half = 0.5 * extents;
    return {centre - half, centre + half};
}

/// The capsule the reader makes of `pos`, `direction` (any non-zero length), `length` and `radius`. The direction's
/// norm must be positive and finite (the reader checks it first).
[[nodiscard]] inline Capsule capsule_from_fields(const Vec3& centre, const Vec3& direction, double length, double radius) {
    // stableNorm: a tiny but valid direction like (1e-200, 0, 0) must not underflow to zero.
    const Vec3 half_axis = (0.5 * length) * Vec3(direction / direction.stableNorm());
    return {centre - half_axis, centre + half_axis, radius};
}

struct AabbFields {
    Vec3 centre;
    Vec3 extents;
};

struct CapsuleFields {
    Vec3 centre;
    Vec3 direction;
    double length = 0.0;
};

/// Fields that aabb_from_fields turns back into `box` bit for bit, per axis: the centre and extent rounded to
/// nearest, else the first pair within three units in the last place of them that does, else the nearest ones.
/// Some boxes have none (corners an odd number of units in the last place apart, in the binade of the centre); the
/// box the reader makes of the nearest fields then has such fields, so a box read back is written back the same.
[[nodiscard]] AabbFields exact_aabb_fields(const Aabb& box);

/// Likewise for capsule_from_fields: the centre, unit direction and length, with the length (up to four units in the
/// last place) and the centre's components (up to three) moved until the ends come back exactly, where they can;
/// the direction is not searched, so a capsule read back does not always come back exactly again.
[[nodiscard]] CapsuleFields exact_capsule_fields(const Capsule& capsule);

}  // namespace hbvh::detail
