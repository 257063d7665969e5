// SPDX-License-Identifier: MIT
// OBB fitters: Gottschalk's covariance box, and the smallest box over several candidate orientations.
#include <algorithm>
#include <utility>
#include <vector>

#include "convex_hull.hpp"
#include "frames.hpp"
#include "hbvh/assert.hpp"
#include "hbvh/fit/fit.hpp"

namespace hbvh {
namespace {

/// The hull vertices and largest radius: enough to rank orientations in O(hull size) each.
detail::PointProxy make_proxy(std::span<const Sphere> spheres, const detail::HullSummary& hull) {
    detail::PointProxy proxy;
    proxy.points.reserve(hull.vertices.size());
    for (std::uint32_t i : hull.vertices) proxy.points.push_back(spheres[i].center);
    for (const Sphere& s : spheres) proxy.max_radius = std::max(proxy.max_radius, s.radius);
    return proxy;
}

}  // namespace

Obb fit_obb_covariance(std::span<const Sphere> spheres) {
    HBVH_ASSERT(!spheres.empty());
    // Gottschalk, Lin & Manocha 1996 (OBBTree, §4): the hull's surface covariance is insensitive to how
    // densely each region is sampled, unlike the raw points' covariance.
    return detail::obb_with_axes(spheres, detail::principal_frame(detail::summarize_hull(spheres).covariance));
}

Obb fit_obb(std::span<const Sphere> spheres, std::span<const Mat3> hint_axes) {
    HBVH_ASSERT(!spheres.empty());
    const detail::HullSummary hull = detail::summarize_hull(spheres);
    const detail::PointProxy proxy = make_proxy(spheres, hull);
    const Mat3 covariance_frame = detail::principal_frame(hull.covariance);

    // Stage 1: rank every candidate orientation on the proxy (hull vertices), O(hull size) each, so that
    // many hints stay cheap. World axes and the covariance frame are exact candidates in stage 3 anyway.
    std::vector<Mat3> candidates;
    candidates.reserve(hint_axes.size() + 24);
    for (const Mat3& axes : hint_axes) candidates.push_back(detail::proper_frame(axes));
    for (const Mat3& axes : detail::dito_frames(spheres)) candidates.push_back(axes);
    candidates.push_back(covariance_frame);
    candidates.push_back(Mat3::Identity());
    std::vector<std::pair<double, std::size_t>> ranked;
    ranked.reserve(candidates.size());
    for (std::size_t i = 0; i < candidates.size(); ++i)
        ranked.emplace_back(detail::proxy_obb_volume(proxy, candidates[i]), i);
    // Ties keep the earlier candidate, so the result does not depend on sort internals.
    const std::size_t keep = std::min<std::size_t>(2, ranked.size());
    std::partial_sort(ranked.begin(), ranked.begin() + static_cast<std::ptrdiff_t>(keep), ranked.end());

    // Stage 2: polish the best-ranked frame with a small deterministic rotation search.
    std::vector<Mat3> finalists{Mat3::Identity(), covariance_frame};
    for (std::size_t i = 0; i < keep; ++i) finalists.push_back(candidates[ranked[i].second]);
    finalists.push_back(detail::refine_frame(proxy, candidates[ranked.front().second]));

    // Stage 3: exact boxes over every sphere for the finalists. The AABB and covariance frames are among
    // them, so the result is never larger than fit_aabb or fit_obb_covariance.
    Obb best = detail::obb_with_axes(spheres, finalists.front());
    for (std::size_t i = 1; i < finalists.size(); ++i) {
        Obb box = detail::obb_with_axes(spheres, finalists[i]);
        if (box.volume() < best.volume()) best = std::move(box);
    }
    return best;
}

}  // namespace hbvh
