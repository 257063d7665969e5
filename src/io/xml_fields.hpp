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

/// Fields that aabb_from_fields turns back into `box` bit for bit: the centre and extents rounded to nearest, else
/// the first pair within a few units in the last place of them that does (found for every box tried,
/// tests/io/test_xml.cpp); the nearest ones where none does.
[[nodiscard]] AabbFields exact_aabb_fields(const Aabb& box);

/// Likewise for capsule_from_fields: the centre, unit direction and length, with the length and the centre's
/// components moved by a few units in the last place until the ends come back exactly, where they can.
[[nodiscard]] CapsuleFields exact_capsule_fields(const Capsule& capsule);

}  // namespace hbvh::detail
