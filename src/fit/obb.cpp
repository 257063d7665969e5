// SPDX-License-Identifier: MIT
// OBB fitters: Gottschalk's covariance box, and the smallest box over several candidate orientations.
#include <algorithm>
#include <utility>
#include <vector>

#include "convex_hull.hpp"
#include "fit_context.hpp"
#include "frames.hpp"
#include "hbvh/assert.hpp"
#include "hbvh/fit/fit.hpp"

namespace hbvh {

Obb fit_obb_covariance(std::span<const Sphere> spheres) {
    HBVH_ASSERT(!spheres.empty());
    // Gottschalk, Lin & Manocha 1996 (OBBTree, §4): the hull's surface covariance is insensitive to how
    // densely each region is sampled, unlike the raw points' covariance.
    return detail::obb_with_axes(spheres, detail::principal_frame(detail::summarize_hull(spheres).covariance));
}

Obb fit_obb(std::span<const Sphere> spheres, std::span<const Mat3> hint_axes) {
    HBVH_ASSERT(!spheres.empty());
    return detail::fit_obb_in(detail::make_fit_context(spheres, hint_axes), spheres);
}

namespace detail {

Obb fit_obb_in(const FitContext& context, std::span<const Sphere> spheres) {
    const HullSummary& hull = context.hull;
    const SphereProxy& proxy = context.proxy;
    const Mat3 covariance_frame = principal_frame(hull.covariance);

    // Stage 1: rank every candidate orientation on the proxy (hull vertices and spheres of positive radius),
    // O(proxy size) each, so that many hints stay cheap.
    std::vector<Mat3> candidates;
    candidates.reserve(context.hints.size() + context.dito.size() + hull.face_normals.size() + 5);
    for (const Mat3& axes : context.hints) candidates.push_back(axes);
    for (const Mat3& axes : context.dito) candidates.push_back(axes);
    // Face-flush frames: along each large hull face normal and each covariance axis (for a flat set the
    // smallest axis is the plane's normal, and the 2-D rectangle step then finds the best in-plane box).
    std::vector<Vec3> normals = hull.face_normals;
    for (int k = 0; k < 3; ++k) normals.push_back(covariance_frame.col(k));
    for (const Mat3& axes : face_flush_frames(proxy, normals)) candidates.push_back(axes);
    candidates.push_back(covariance_frame);
    candidates.push_back(Mat3::Identity());
    std::vector<std::pair<double, std::size_t>> ranked;
    ranked.reserve(candidates.size());
    for (std::size_t i = 0; i < candidates.size(); ++i)
        ranked.emplace_back(proxy_obb_volume(proxy, candidates[i]), i);
    // Ties keep the earlier candidate, so the result does not depend on sort internals.
    const std::size_t keep = std::min<std::size_t>(2, ranked.size());
    std::partial_sort(ranked.begin(), ranked.begin() + static_cast<std::ptrdiff_t>(keep), ranked.end());

    // Stage 2: polish the best-ranked frame with a small deterministic rotation search.
    std::vector<Mat3> finalists{Mat3::Identity(), covariance_frame};
    for (std::size_t i = 0; i < keep; ++i) finalists.push_back(candidates[ranked[i].second]);
    finalists.push_back(refine_frame(proxy, candidates[ranked.front().second]));

    // Stage 3: exact boxes over every sphere for the finalists. The AABB and covariance frames are among
    // them, so the result is never larger than fit_aabb or fit_obb_covariance.
    Obb best = obb_with_axes(spheres, finalists.front());
    for (std::size_t i = 1; i < finalists.size(); ++i) {
        Obb box = obb_with_axes(spheres, finalists[i]);
        if (box.volume() < best.volume()) best = std::move(box);
    }
    return best;
}

}  // namespace detail
}  // namespace hbvh
