// SPDX-License-Identifier: MIT
// Internal: candidate orientations shared by the OBB and capsule fitters, and box evaluation per frame.
#pragma once

#include <span>
#include <vector>

#include "hbvh/geometry/obb.hpp"

namespace hbvh::detail {

/// A cheap stand-in for a sphere set when ranking many orientations: points whose every sphere lies
/// within `max_radius` of their convex hull (hull vertices of the centres plus the largest radius).
/// Extents measured on it are upper bounds, exact when all radii are equal.
struct PointProxy {
    std::vector<Vec3> points;
    double max_radius = 0.0;
};

/// `axes` made a proper rotation: columns orthonormalised in order (Gram-Schmidt), the last one
/// completed by a cross product so that det = +1. A column of zero length is replaced by any perpendicular.
[[nodiscard]] Mat3 proper_frame(const Mat3& axes);

/// Eigenvectors of a symmetric 3x3 matrix as a proper rotation, column 0 the largest eigenvalue's.
[[nodiscard]] Mat3 principal_frame(const Mat3& covariance);

/// A proper rotation whose column 0 is `axis` (need not be unit; zero gives the identity).
[[nodiscard]] Mat3 frame_from_axis(const Vec3& axis);

/// DiTO candidate frames (Larsson & Källberg 2011): from the extremal spheres along 13 fixed directions,
/// the farthest pair, the farthest sphere from their line and the two apexes off that triangle's plane
/// give up to 7 triangles; each triangle edge with the triangle normal is one frame. Empty when all
/// centres coincide.
[[nodiscard]] std::vector<Mat3> dito_frames(std::span<const Sphere> spheres);

/// The smallest box with axes `rotation` containing every sphere exactly (in double arithmetic:
/// Obb::contains with zero tolerance holds for each input). O(n).
[[nodiscard]] Obb obb_with_axes(std::span<const Sphere> spheres, const Mat3& rotation);

/// Volume of the box with axes `rotation` around `proxy` (an upper bound on obb_with_axes' volume).
[[nodiscard]] double proxy_obb_volume(const PointProxy& proxy, const Mat3& rotation);

/// Deterministic local search (pattern search over small rotations about the frame's own axes, with
/// halving step) that lowers proxy_obb_volume. Returns the improved frame; never a worse one.
[[nodiscard]] Mat3 refine_frame(const PointProxy& proxy, const Mat3& rotation);

}  // namespace hbvh::detail
