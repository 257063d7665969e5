// SPDX-License-Identifier: MIT
// Internal: the convex hull of points in a plane.
#pragma once

#include <vector>

#include <Eigen/Core>

namespace hbvh::detail {

/// Convex hull of 2-D points, counter-clockwise, without collinear points (Andrew's monotone chain), into
/// `hull`. `points` is sorted in place. Fewer than three points come back just sorted. Both vectors are the
/// caller's so that loops over many planes reuse their storage: the fitters call this thousands of times
/// per build on a few dozen points, where allocation cost as much as the hull itself.
void hull_2d(std::vector<Eigen::Vector2d>& points, std::vector<Eigen::Vector2d>& hull);

}  // namespace hbvh::detail
