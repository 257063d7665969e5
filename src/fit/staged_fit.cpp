// SPDX-License-Identifier: MIT
// fit_best's steps: the kinds in order, the exact sphere and the capsule only where they can still win.
#include "staged_fit.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>

#include "capsule_bound.hpp"
#include "sphere_floor.hpp"

#include "hbvh/assert.hpp"
#include "hbvh/fit/fit.hpp"

namespace hbvh::detail {

std::vector<Sphere> without_repeats(std::span<const Sphere> spheres) {
    std::vector<std::uint32_t> order(spheres.size());
    for (std::uint32_t i = 0; i < order.size(); ++i) order[i] = i;
    const auto key = [&](std::uint32_t i) {
        const Sphere& s = spheres[i];
        return std::array{s.center.x(), s.center.y(), s.center.z(), s.radius};
    };
    std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return key(a) < key(b); });
    std::vector<bool> repeat(spheres.size(), false);
    bool any = false;
    for (std::size_t i = 1; i < order.size(); ++i)
        if (key(order[i]) == key(order[i - 1])) repeat[order[i]] = any = true;
    std::vector<Sphere> kept;
    if (!any) return kept;
    for (std::size_t i = 0; i < spheres.size(); ++i)
        if (!repeat[i]) kept.push_back(spheres[i]);
    return kept;
}

namespace {

const Sphere& enclosing_sphere(FitStages& stages, std::span<const Sphere> spheres) {
    if (!stages.enclosing) stages.enclosing = fit_sphere(spheres);
    return *stages.enclosing;
}

/// Keeps `candidate` when it is cheaper than the best so far (strict '<': the earlier, simpler kind wins ties:
/// AABB before OBB before sphere before capsule).
void consider(FitStages& stages, BoundingVolume candidate, const VolumePolicy& policy) {
    const double candidate_cost = policy.weighted_volume(candidate);
    if (!stages.best || candidate_cost < stages.best_cost) {
        stages.best = std::move(candidate);
        stages.best_cost = candidate_cost;
    }
}

}  // namespace

FitStages start_fit(std::span<const Sphere> spheres, const VolumePolicy& policy, std::span<const Mat3> hint_axes) {
    HBVH_ASSERT(!spheres.empty());
    FitStages stages;
    // The OBB and capsule fitters need the same hull, proxy, DiTO frames and hints, and the capsule
    // fitter needs the enclosing sphere: compute each once, and only when some allowed kind needs it.
    // The results are bit for bit those of the separate fitters.
    if (policy.is_allowed(BvType::obb) || policy.is_allowed(BvType::capsule))
        stages.context = make_fit_context(spheres, hint_axes);
    double widest = 0.0;     // the widest extent of the fitted boxes: the sphere is at least as wide
    double magnitude = 0.0;  // and the largest coordinate they were rounded at
    // The cross-sections for the capsule bound: the OBB's axes once it is fitted (a tight box's axes give
    // the strongest bound, so they go first), then the world axes.
    stages.bound_planes = {Mat3::Identity()};
    for (BvType type : all_bv_types) {
        if (!policy.is_allowed(type)) continue;
        if (type == BvType::capsule && stages.best && policy.measure == NodeMeasure::volume) {
            // The capsule fitter costs more than the other three together, and on compact sets a box or sphere
            // usually wins by far: a lower bound of every capsule around the spheres (capsule_bound.hpp) either
            // rules it out or is kept as the floor of the pending step. The bound is computed in rounded
            // arithmetic from coordinates relative to the set; the margin is far above that rounding, so a skip
            // never depends on it. (It bounds a volume, so only the volume measure can use it.)
            constexpr double rounding_margin = 1e-6;
            const double scale = policy.weight_of(BvType::capsule) * (1.0 - rounding_margin);
            const double floor =
                scale * capsule_volume_lower_bound(stages.context->proxy, stages.bound_planes, stages.best_cost / scale);
            if (floor >= stages.best_cost) continue;
            stages.capsule_pending = true;
            stages.capsule_floor = floor;
            static_assert(all_bv_types.back() == BvType::capsule, "the pending step must be the last");
            break;
        }
        if (type == BvType::sphere && stages.best && least_sphere_cost(widest, magnitude, policy) >= stages.best_cost)
            continue;
        BoundingVolume candidate = [&]() -> BoundingVolume {
            switch (type) {
                case BvType::aabb: return fit_aabb(spheres);
                case BvType::obb: return fit_obb_in(*stages.context, spheres);
                case BvType::sphere: return enclosing_sphere(stages, spheres);
                case BvType::capsule: return fit_capsule_in(*stages.context, spheres, enclosing_sphere(stages, spheres));
            }
            HBVH_ASSERT(false);
            return fit_aabb(spheres);
        }();
        if (const Obb* box = std::get_if<Obb>(&candidate)) {
            stages.bound_planes.insert(stages.bound_planes.begin(), box->rotation);
            widest = std::max(widest, 2.0 * box->half_extents.maxCoeff());
            magnitude = std::max(magnitude, box->center.cwiseAbs().maxCoeff() + box->half_extents.maxCoeff());
        } else if (const Aabb* aabb = std::get_if<Aabb>(&candidate)) {
            widest = std::max(widest, (aabb->max - aabb->min).maxCoeff());
            magnitude = std::max({magnitude, aabb->min.cwiseAbs().maxCoeff(), aabb->max.cwiseAbs().maxCoeff()});
        }
        consider(stages, std::move(candidate), policy);
    }
    HBVH_ASSERT(stages.best.has_value());
    return stages;
}

OwnedFit start_owned_fit(std::vector<Sphere> spheres, const VolumePolicy& policy, std::span<const Mat3> hint_axes) {
    OwnedFit fit;
    fit.spheres = std::move(spheres);
    if (fit.spheres.size() > repeats_checked_above)  // as fit_best does
        if (std::vector<Sphere> distinct = without_repeats(fit.spheres); !distinct.empty())
            fit.spheres = std::move(distinct);
    fit.stages = start_fit(fit.spheres, policy, hint_axes);
    return fit;
}

void FitStages::finish(std::span<const Sphere> spheres, const VolumePolicy& policy) {
    if (!capsule_pending) return;
    consider(*this, fit_capsule_in(*context, spheres, enclosing_sphere(*this, spheres)), policy);
    capsule_pending = false;  // only now: if the fitter threw, the step is still pending and a retry runs it
}

}  // namespace hbvh::detail
