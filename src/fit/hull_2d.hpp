// SPDX-License-Identifier: MIT
// Internal: the convex hull of points in a plane.
#pragma once

#include <cstddef>
#include <vector>

#include <Eigen/Core>

namespace hbvh::detail {

/// Convex hull of 2-D points, counter-clockwise, without collinear points (Andrew's monotone chain), into
/// `hull`. `points` is sorted in place. Fewer than three points come back just sorted. Both vectors are the
/// caller's so that loops over many planes reuse their storage: the fitters call this thousands of times
/// per build on a few dozen points, where allocation cost as much as the hull itself.
void hull_2d(std::vector<Eigen::Vector2d>& points, std::vector<Eigen::Vector2d>& hull);

/// For edge i of a convex polygon (hull[i] to hull[i + 1], counter-clockwise, as hull_2d returns it), the
/// vertices extremal along the edge's direction (lowest, highest) and farthest from the edge's line.
struct EdgeExtremes {
    std::size_t lowest_along = 0;
    std::size_t highest_along = 0;
    std::size_t farthest_across = 0;
};

/// Edges of this many vertices or fewer are measured by brute force (O(h^2), exact, and cheaper than
/// calipers' bookkeeping on small polygons); larger ones by rotating calipers (O(h)).
inline constexpr std::size_t calipers_above = 64;

/// EdgeExtremes of every edge by rotating calipers (Toussaint 1983): as the edge turns counter-clockwise
/// each extremal vertex moves forward only, so the three pointers together advance O(h) steps. In rounded
/// arithmetic a pointer may stop one vertex short on a near-flat stretch, where the values differ by
/// rounding only. Zero-length edges get the previous edge's extremes. Precondition: hull.size() >= 3.
void edge_extremes(const std::vector<Eigen::Vector2d>& hull, std::vector<EdgeExtremes>& extremes);

}  // namespace hbvh::detail
