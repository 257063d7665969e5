// SPDX-License-Identifier: MIT
// Internal: a floor under the price of every sphere around a set, from how wide the set is, so that the exact
// enclosing sphere (CGAL) is computed only where it can still be the cheapest candidate.
#pragma once

#include <algorithm>

#include "hbvh/fit/volume_policy.hpp"
#include "hbvh/geometry/sphere.hpp"

namespace hbvh::detail {

/// The least weighted measure under `policy` of any sphere around a set that is `widest` wide along some axis,
/// the width taken from boxes rounded at coordinates up to `magnitude`. Such a sphere's radius is at least half
/// the width, and a sphere's measure (its volume, or the calibrated Minkowski measure) grows with its radius. The
/// radius gives up a relative 1e-6 and 2^-40 of the magnitude, far more than the boxes' rounding pads (for a lone
/// point the pads are all the width there is), so no sphere around the set is priced below this.
[[nodiscard]] inline double least_sphere_cost(double widest, double magnitude, const VolumePolicy& policy) {
    const double radius = std::max(0.0, 0.5 * widest * (1.0 - 1e-6) - 0x1.0p-40 * magnitude);
    return policy.weighted_volume(Sphere{Vec3::Zero(), radius});
}

}  // namespace hbvh::detail
