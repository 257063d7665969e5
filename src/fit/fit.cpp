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

#include "capsule_bound.hpp"
#include "fit_context.hpp"
#include "rounding_pad.hpp"
#include "sphere_floor.hpp"

#include "hbvh/assert.hpp"

namespace hbvh {
namespace {

/// True when no capsule around the context's spheres can cost less than `best_cost`, so fitting one
/// could not change fit_best's answer (it keeps the earlier kind on ties). The capsule fitter costs
/// more than the other three together; on compact sets a box or sphere usually wins by far.
bool capsule_cannot_win(const detail::FitContext& context, std::span<const Mat3> planes, const VolumePolicy& policy,
                        double best_cost) {
    // The bound is computed in rounded arithmetic from coordinates relative to the set; this margin is
    // far above that rounding, so a skip never depends on it.
    constexpr double rounding_margin = 1e-6;
    const double scale = policy.weight_of(BvType::capsule) * (1.0 - rounding_margin);
    return scale * detail::capsule_volume_lower_bound(context.proxy, planes, best_cost / scale) >= best_cost;
}

}  // namespace

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

namespace {
/// `spheres` without exact repeats, first occurrences in their original order; empty when there are none
/// to drop. Repeats change no BV, but degenerate sets (10^5 copies of one sphere: a flat hull, a zero
/// covariance) sent the hull and search steps down slow paths whose cost grew with the copies.
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
}  // namespace

BoundingVolume fit_best(std::span<const Sphere> spheres, const VolumePolicy& policy, std::span<const Mat3> hint_axes) {
    HBVH_ASSERT(!spheres.empty());
    // Small sets are fitted as they are: the check would cost more than the repeats it could save.
    if (spheres.size() > 256) {
        const std::vector<Sphere> distinct = without_repeats(spheres);
        if (!distinct.empty()) return fit_best(distinct, policy, hint_axes);
    }
    // The OBB and capsule fitters need the same hull, proxy, DiTO frames and hints, and the capsule
    // fitter needs the enclosing sphere: compute each once, and only when some allowed kind needs it.
    // The results are bit for bit those of the separate fitters.
    const bool wants_obb = policy.is_allowed(BvType::obb);
    const bool wants_capsule = policy.is_allowed(BvType::capsule);
    std::optional<detail::FitContext> context;
    if (wants_obb || wants_capsule) context = detail::make_fit_context(spheres, hint_axes);
    // The exact enclosing sphere (CGAL) is made when first needed: by the sphere candidate, unless its floor says
    // it cannot win, or by the capsule fitter, unless that is skipped.
    std::optional<Sphere> enclosing;
    const auto enclosing_sphere = [&]() -> const Sphere& {
        if (!enclosing) enclosing = fit_sphere(spheres);
        return *enclosing;
    };
    double widest = 0.0;     // the widest extent of the fitted boxes: the sphere is at least as wide
    double magnitude = 0.0;  // and the largest coordinate they were rounded at

    std::optional<BoundingVolume> best;
    double best_cost = std::numeric_limits<double>::infinity();
    // The cross-sections for the capsule bound: the OBB's axes once it is fitted (a tight box's axes give
    // the strongest bound, so they go first), then the world axes.
    std::vector<Mat3> bound_planes{Mat3::Identity()};
    for (BvType type : all_bv_types) {
        if (!policy.is_allowed(type)) continue;
        // The bound is on a capsule's volume, so it can only skip the fit when volume is the measure.
        if (type == BvType::capsule && best && policy.measure == NodeMeasure::volume &&
            capsule_cannot_win(*context, bound_planes, policy, best_cost))
            continue;
        if (type == BvType::sphere && best && detail::least_sphere_cost(widest, magnitude, policy) >= best_cost) continue;
        BoundingVolume candidate = [&]() -> BoundingVolume {
            switch (type) {
                case BvType::aabb: return fit_aabb(spheres);
                case BvType::obb: return detail::fit_obb_in(*context, spheres);
                case BvType::sphere: return enclosing_sphere();
                case BvType::capsule: return detail::fit_capsule_in(*context, spheres, enclosing_sphere());
            }
            HBVH_ASSERT(false);
            return fit_aabb(spheres);
        }();
        if (const Obb* box = std::get_if<Obb>(&candidate)) {
            bound_planes.insert(bound_planes.begin(), box->rotation);
            widest = std::max(widest, 2.0 * box->half_extents.maxCoeff());
            magnitude = std::max(magnitude, box->center.cwiseAbs().maxCoeff() + box->half_extents.maxCoeff());
        } else if (const Aabb* aabb = std::get_if<Aabb>(&candidate)) {
            widest = std::max(widest, (aabb->max - aabb->min).maxCoeff());
            magnitude = std::max({magnitude, aabb->min.cwiseAbs().maxCoeff(), aabb->max.cwiseAbs().maxCoeff()});
        }
        const double candidate_cost = policy.weighted_volume(candidate);
        // Strict '<' keeps the earlier (simpler) kind on ties: AABB before OBB before sphere before capsule.
        if (!best || candidate_cost < best_cost) {
            best = std::move(candidate);
            best_cost = candidate_cost;
        }
    }
    HBVH_ASSERT(best.has_value());
    return *best;
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
