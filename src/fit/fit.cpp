// SPDX-License-Identifier: MIT
// Fitter dispatch, the exact AABB, and the choice among kinds. The per-kind fitters live in
// sphere.cpp, obb.cpp and capsule.cpp.
#include "hbvh/fit/fit.hpp"

#include <limits>

#include "hbvh/assert.hpp"

namespace hbvh {

Aabb fit_aabb(std::span<const Sphere> spheres) {
    HBVH_ASSERT(!spheres.empty());
    Aabb box = Aabb::empty();
    for (const Sphere& s : spheres) {
        const Vec3 r = Vec3::Constant(s.radius);
        box = box.merged({s.center - r, s.center + r});
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
    std::optional<BoundingVolume> best;
    double best_cost = std::numeric_limits<double>::infinity();
    for (BvType type : all_bv_types) {
        if (!policy.is_allowed(type)) continue;
        BoundingVolume candidate = fit(type, spheres, hint_axes);
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
    if (const Obb* box = std::get_if<Obb>(&bv)) {
        // Boxes that share an orientation (common in artists' models) would only repeat work.
        for (const Mat3& axes : hint_axes)
            if ((axes - box->rotation).cwiseAbs().maxCoeff() < 1e-9) return;
        hint_axes.push_back(box->rotation);
    }
}

}  // namespace hbvh
