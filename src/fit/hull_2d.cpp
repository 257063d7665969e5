// SPDX-License-Identifier: MIT
// Andrew's monotone chain, shared by the face-flush frames and the capsule lower bound.
#include "hull_2d.hpp"

#include <algorithm>

namespace hbvh::detail {

void hull_2d(std::vector<Eigen::Vector2d>& points, std::vector<Eigen::Vector2d>& hull) {
    std::sort(points.begin(), points.end(),
              [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y()); });
    if (points.size() < 3) {
        hull = points;
        return;
    }
    auto turn = [](const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
        return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
    };
    hull.resize(2 * points.size());
    std::size_t k = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
        while (k >= 2 && turn(hull[k - 2], hull[k - 1], points[i]) <= 0.0) --k;
        hull[k++] = points[i];
    }
    for (std::size_t i = points.size() - 1, lower = k + 1; i-- > 0;) {
        while (k >= lower && turn(hull[k - 2], hull[k - 1], points[i]) <= 0.0) --k;
        hull[k++] = points[i];
    }
    hull.resize(k - 1);
}

void edge_extremes(const std::vector<Eigen::Vector2d>& hull, std::vector<EdgeExtremes>& extremes) {
    const std::size_t h = hull.size();
    extremes.assign(h, {});
    const auto next = [h](std::size_t j) { return j + 1 == h ? std::size_t{0} : j + 1; };
    // Moves `j` forward while the next vertex scores strictly higher; `score` is linear, so over a convex
    // polygon it rises to one maximum and falls again. At most h steps, so a flat (rounded) stretch cannot loop.
    const auto climb = [&](std::size_t j, const auto& score) {
        for (std::size_t steps = 0; steps < h && score(hull[next(j)]) > score(hull[j]); ++steps) j = next(j);
        return j;
    };
    // Edge 0 starts the pointers from a full scan, so that each begins at its true maximum.
    const auto argmax = [&](const auto& score) {
        std::size_t best = 0;
        for (std::size_t j = 1; j < h; ++j)
            if (score(hull[j]) > score(hull[best])) best = j;
        return best;
    };
    EdgeExtremes current;
    bool started = false;
    for (std::size_t i = 0; i < h; ++i) {
        const Eigen::Vector2d edge = hull[next(i)] - hull[i];
        if (!(edge.squaredNorm() > 0.0)) {
            extremes[i] = current;
            continue;
        }
        // Left of a counter-clockwise edge is inside, so the farthest vertex is the highest along (-y, x).
        const Eigen::Vector2d inward(-edge.y(), edge.x());
        const auto along = [&](const Eigen::Vector2d& p) { return p.dot(edge); };
        const auto against = [&](const Eigen::Vector2d& p) { return -p.dot(edge); };
        const auto across = [&](const Eigen::Vector2d& p) { return p.dot(inward); };
        if (!started) {
            current = {argmax(against), argmax(along), argmax(across)};
            started = true;
        } else {
            current = {climb(current.lowest_along, against), climb(current.highest_along, along),
                       climb(current.farthest_across, across)};
        }
        extremes[i] = current;
    }
}

}  // namespace hbvh::detail
