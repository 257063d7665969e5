// SPDX-License-Identifier: MIT
// Internal: the work the OBB and capsule fitters share (hull, proxy, DiTO frames, selected hints), so
// that fit_best computes it once per call instead of once per kind.
#pragma once

#include <span>
#include <vector>

#include "frames.hpp"
#include "hbvh/geometry/capsule.hpp"
#include "hbvh/geometry/sphere.hpp"

namespace hbvh::detail {

/// Everything about a sphere set that does not depend on the BV kind being fitted.
struct FitContext {
    HullSummary hull;
    SphereProxy proxy;
    std::vector<Mat3> dito;   ///< dito_frames of the spheres.
    std::vector<Mat3> hints;  ///< select_hints of the caller's hint axes on the proxy.
};

/// The context of `spheres` with extra orientations `hint_axes`. Precondition: spheres non-empty.
[[nodiscard]] FitContext make_fit_context(std::span<const Sphere> spheres, std::span<const Mat3> hint_axes);

/// fit_obb on a context made from the same spheres.
[[nodiscard]] Obb fit_obb_in(const FitContext& context, std::span<const Sphere> spheres);

/// fit_capsule on a context made from the same spheres; `enclosing` is their fit_sphere.
[[nodiscard]] Capsule fit_capsule_in(const FitContext& context, std::span<const Sphere> spheres,
                                     const Sphere& enclosing);

}  // namespace hbvh::detail
