// SPDX-License-Identifier: MIT
// The 2-D hull and its rotating calipers (src/fit/hull_2d.hpp), which the face-flush frames and the
// capsule bound use on big hulls: every edge's extremal vertices must score what a scan of every vertex does.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include <Eigen/Geometry>

#include "../../src/fit/hull_2d.hpp"
#include "hbvh/scene/generate.hpp"

namespace hbvh {
namespace {

/// Points near an ellipse with a random tilt and aspect, plus points inside it: a hull of most of the rim.
std::vector<Eigen::Vector2d> rim_points(SplitMix64& rng, std::size_t count) {
    const double a = std::pow(10.0, rng.uniform(-3.0, 3.0));
    const double b = a * rng.uniform(0.01, 1.0);
    const double tilt = rng.uniform(0.0, std::numbers::pi);
    const Eigen::Vector2d offset(rng.uniform(-1e3, 1e3), rng.uniform(-1e3, 1e3));
    std::vector<Eigen::Vector2d> points;
    for (std::size_t i = 0; i < count; ++i) {
        const double t = rng.uniform(0.0, 2.0 * std::numbers::pi);
        const double r = i % 4 == 0 ? rng.uniform(0.0, 1.0) : 1.0 - rng.uniform(0.0, 1e-3);
        const Eigen::Vector2d local(a * r * std::cos(t), b * r * std::sin(t));
        points.push_back(offset + Eigen::Rotation2Dd(tilt) * local);
    }
    return points;
}

TEST(Hull2d, CalipersFindEveryEdgesExtremes) {
    SplitMix64 rng(2718);
    int polygons_above_threshold = 0;
    for (int polygon = 0; polygon < 40; ++polygon) {
        std::vector<Eigen::Vector2d> points = rim_points(rng, 3 + rng.below(3000));
        std::vector<Eigen::Vector2d> hull;
        detail::hull_2d(points, hull);
        if (hull.size() < 3) continue;
        if (hull.size() > detail::calipers_above) ++polygons_above_threshold;
        std::vector<detail::EdgeExtremes> extremes;
        detail::edge_extremes(hull, extremes);
        ASSERT_EQ(extremes.size(), hull.size());
        double size = 0.0;
        for (const Eigen::Vector2d& p : hull) size = std::max(size, (p - hull.front()).norm());
        for (std::size_t i = 0; i < hull.size(); ++i) {
            const Eigen::Vector2d edge = hull[(i + 1) % hull.size()] - hull[i];
            const Eigen::Vector2d d = edge.normalized();
            const Eigen::Vector2d inward(-d.y(), d.x());
            double low = std::numeric_limits<double>::infinity();
            double high = -low;
            double across = -low;
            for (const Eigen::Vector2d& q : hull) {
                low = std::min(low, (q - hull[i]).dot(d));
                high = std::max(high, (q - hull[i]).dot(d));
                across = std::max(across, (q - hull[i]).dot(inward));
            }
            // Relative to the polygon: a pointer may stop a vertex short only where the scores tie up to rounding.
            const double tolerance = 1e-12 * size;
            EXPECT_NEAR((hull[extremes[i].lowest_along] - hull[i]).dot(d), low, tolerance) << polygon << " edge " << i;
            EXPECT_NEAR((hull[extremes[i].highest_along] - hull[i]).dot(d), high, tolerance) << polygon << " edge " << i;
            EXPECT_NEAR((hull[extremes[i].farthest_across] - hull[i]).dot(inward), across, tolerance)
                << polygon << " edge " << i;
        }
    }
    EXPECT_GT(polygons_above_threshold, 10);  // the calipers' range, not only the brute-force one
}

TEST(Hull2d, CalipersOnATriangleAndASquare) {
    const std::vector<Eigen::Vector2d> triangle{{0, 0}, {2, 0}, {0, 1}};
    std::vector<detail::EdgeExtremes> extremes;
    detail::edge_extremes(triangle, extremes);
    ASSERT_EQ(extremes.size(), 3u);
    EXPECT_EQ(extremes[0].farthest_across, 2u);   // edge (0,0)-(2,0): the apex (0,1)
    EXPECT_EQ(extremes[0].highest_along, 1u);
    EXPECT_EQ(extremes[1].farthest_across, 0u);   // edge (2,0)-(0,1): the origin
    const std::vector<Eigen::Vector2d> square{{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    detail::edge_extremes(square, extremes);
    for (std::size_t i = 0; i < 4; ++i) {
        const Eigen::Vector2d edge = square[(i + 1) % 4] - square[i];
        const Eigen::Vector2d inward(-edge.y(), edge.x());
        EXPECT_DOUBLE_EQ((square[extremes[i].farthest_across] - square[i]).dot(inward), 1.0) << i;
        EXPECT_DOUBLE_EQ((square[extremes[i].highest_along] - square[i]).dot(edge), 1.0) << i;
        EXPECT_DOUBLE_EQ((square[extremes[i].lowest_along] - square[i]).dot(edge), 0.0) << i;
    }
}

}  // namespace
}  // namespace hbvh
