// SPDX-License-Identifier: MIT
// fit_fast: a cheap enclosing fitter for big groups (scale's, and anyone's with many primitives per node).
#pragma once

#include <span>

#include "hbvh/fit/volume_policy.hpp"
#include "hbvh/geometry/bounding_volume.hpp"

namespace hbvh {

/// The cheap enclosing fitter used for big groups: the smallest weighted volume, over the allowed kinds,
/// of the exact AABB, the exact sphere, OBBs in the world frame, the principal frame of the centres and
/// the frames of any boxes among `hints`, and capsules on the principal axis and on the axes of any
/// capsules among `hints`. Every result contains all `spheres`. Precondition: spheres non-empty.
[[nodiscard]] BoundingVolume fit_fast(std::span<const Sphere> spheres, std::span<const BoundingVolume> hints,
                                      const VolumePolicy& policy);

/// How fit_fast fits the sphere: exactly (CGAL's minimum sphere), or quickly around the better of the
/// box centre and the mean centre (encloses as surely, a little larger; for pricing candidates).
enum class FastFitMode { exact_sphere, quick_sphere };
/// fit_fast with a choice of sphere fitter.
[[nodiscard]] BoundingVolume fit_fast(std::span<const Sphere> spheres, std::span<const BoundingVolume> hints,
                                      const VolumePolicy& policy, FastFitMode mode);

}  // namespace hbvh
