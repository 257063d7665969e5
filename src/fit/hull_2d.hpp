// SPDX-License-Identifier: MIT
// Internal: the convex hull of points in a plane.
#pragma once

#include <vector>

#include <Eigen/Core>

namespace hbvh::detail {

/// Convex hull of 2-D points, counter-clockwise, without collinear points (Andrew's monotone chain).
/// Fewer than three points come back just sorted.
[[nodiscard]] std::vector<Eigen::Vector2d> hull_2d(std::vector<Eigen::Vector2d> points);

}  // namespace hbvh::detail
