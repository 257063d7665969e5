// SPDX-License-Identifier: MIT
// Fitter dispatch, the exact AABB, and the choice among kinds. The per-kind fitters live in
// sphere.cpp, obb.cpp and capsule.cpp.
#include "hbvh/fit/fit.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

#include "rounding_pad.hpp"
#include "staged_fit.hpp"

#include "hbvh/assert.hpp"

namespace hbvh {
Aabb fit_aabb(std::span<const Sphere> spheres) {
    HBVH_ASSERT(!spheres.empty());
    Aabb box = Aabb::empty();
    for (const Sphere& s : spheres) {
        const Vec3 r = Vec3::Constant(s.radius);
        box = box.merged({s.center - r, s.center + r});
    }
    // centre -/+ radius rounds to nearest, by up to half an ulp of |centre| + radius: grow outwards by the
    // fitters' pad of the largest coordinate (which is at least that), so that the box contains every
    // sphere even when re-evaluated with other rounding, and however far from the origin it sits.
    // Per axis: a model spanning 1e150 in x but 1e-150 in y rounds y at 1e-150, and one pad for all axes
    // would inflate the box's volume to infinity (tests/cli/inputs/mixed_scale.xml).
    for (int axis = 0; axis < 3; ++axis) {
        const double pad = detail::rounding_pad(std::max(std::abs(box.min[axis]), std::abs(box.max[axis])));
        box.min[axis] -= pad;
        box.max[axis] += pad;
    }
    return box;
}

BoundingVolume fit(BvType type, std::span<const Sphere> spheres, std::span<const Mat3> hint_axes) {
    switch (type) {
        case BvType::aabb: return fit_aabb(spheres);
        case BvType::obb: return fit_obb(spheres, hint_axes);
        case BvType::sphere: return fit_sphere(spheres);
        case BvType::capsule: return fit_capsule(spheres, hint_axes);
    }
    HBVH_ASSERT(false);
    return fit_aabb(spheres);
}

BoundingVolume fit_best(std::span<const Sphere> spheres, const VolumePolicy& policy, std::span<const Mat3> hint_axes) {
    HBVH_ASSERT(!spheres.empty());
    if (std::none_of(policy.allowed.begin(), policy.allowed.end(), [](bool allowed) { return allowed; })) {
        VolumePolicy every_kind = policy;
        every_kind.allowed.fill(true);
        return fit_best(spheres, every_kind, hint_axes);
    }
    if (spheres.size() > detail::repeats_checked_above) {
        const std::vector<Sphere> distinct = detail::without_repeats(spheres);
        if (!distinct.empty()) return fit_best(distinct, policy, hint_axes);
    }
    // Every step but the capsule's where it may still win, then that one: the staged form the treelet DP uses
    // (src/fit/staged_fit.hpp), run through here so that both give the same answer.
    detail::FitStages stages = detail::start_fit(spheres, policy, hint_axes);
    stages.finish(spheres, policy);
    return *stages.best;
}

void FitInput::add(const BoundingVolume& bv) {
    append_generating_spheres(bv, spheres);
    const Obb* box = std::get_if<Obb>(&bv);
    // Past the cap no hint is added, so none needs to be looked up: O(1) per box at any count. (Comparing
    // every box with every kept one was O(n^2) over a scene of differently oriented boxes: 75 % of a 10^6
    // primitive two-level build.)
    if (box == nullptr || hint_axes.size() >= max_hint_axes) return;
    // Boxes that share an orientation (common in artists' models) would only repeat work. With the cap,
    // comparing with every kept orientation is at most max_hint_axes comparisons and allocates nothing.
    for (const Mat3& axes : hint_axes)
        if ((axes - box->rotation).cwiseAbs().maxCoeff() < 1e-9) return;
    hint_axes.push_back(box->rotation);
}

}  // namespace hbvh
