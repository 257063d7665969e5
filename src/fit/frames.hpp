// SPDX-License-Identifier: MIT
// Internal: candidate orientations shared by the OBB and capsule fitters, and box evaluation per frame.
#pragma once

#include <optional>
#include <span>
#include <vector>

#include "convex_hull.hpp"
#include "hbvh/geometry/obb.hpp"

namespace hbvh::detail {

/// The spheres that can touch the boundary of any convex volume around a set: those centred on a hull
/// vertex, and every sphere of positive radius. A radius-0 point that is not a hull vertex lies in the
/// hull of the others, so a convex volume containing them contains it too; dropping it changes no
/// extent. Ranking orientations on this subset is therefore exact, yet costs O(hull size) for boxes.
struct SphereProxy {
    std::vector<Sphere> spheres;
    std::vector<Vec3> hull_points;  ///< Centres of the hull vertices only: a cheaper, coarser stand-in.
    HullSurface surface;            ///< The hull's surface over hull_points (empty when qhull made the hull).
    double max_radius = 0.0;
};

/// The proxy of `spheres`, whose centres' hull is `hull`.
[[nodiscard]] SphereProxy make_proxy(std::span<const Sphere> spheres, const HullSummary& hull);

/// How many hint frames reach the exact ranking; the rest are dropped by a coarse pre-ranking, so that a
/// node over thousands of differently oriented boxes does not cost (boxes x spheres).
inline constexpr std::size_t max_ranked_hints = 8;

/// The (at most) `limit` hints, made proper, whose boxes around the hull points padded by the largest
/// radius (an upper bound, O(hull size) each) are smallest. All of them, in order, when there are few.
[[nodiscard]] std::vector<Mat3> select_hints(const SphereProxy& proxy, std::span<const Mat3> hints,
                                             std::size_t limit = max_ranked_hints);

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

/// For each unit `normals[i]`, the frame with column 0 along it whose cross-section is the smallest
/// rectangle around the projected hull points (padded by the largest radius): the rectangle has a side along
/// an edge of the projected 2-D hull (Freeman & Shapira 1975), so the edges are the only directions tried.
/// The projected hull is the proxy's surface outline along the normal where it has one (hull_outline). With the hull's face
/// normals this gives boxes with a face flush with a hull face: a heuristic in the spirit of O'Rourke
/// 1985 (whose minimal box has two adjacent faces each containing a hull edge), not a guarantee.
[[nodiscard]] std::vector<Mat3> face_flush_frames(const SphereProxy& proxy, std::span<const Vec3> normals);

/// The 2-D hull of the proxy's hull points projected on (basis.col(1), basis.col(2)) after subtracting
/// `origin`, into `hull`: the projected outline of the proxy's surface along basis.col(0) when it has one of at
/// most calipers_above points (its points lie on the polygon's boundary, perhaps with some on its edges, which
/// the brute-force rectangle and width searches tolerate), else hull_2d of every projected point, counter-clockwise.
/// `scratch` is reused across calls, so that loops over many planes allocate once.
void hull_outline(const SphereProxy& proxy, const Mat3& basis, const Vec3& origin, std::vector<Eigen::Vector2d>& hull,
                  OutlineScratch& scratch);

/// The smallest box with axes `rotation` containing every sphere exactly (in double arithmetic:
/// Obb::contains with zero tolerance holds for each input). O(n).
[[nodiscard]] Obb obb_with_axes(std::span<const Sphere> spheres, const Mat3& rotation);

/// obb_with_axes when that box's volume can be below `limit`, else nothing (often after a few spheres): the
/// box's volume is at least the product of its first pass's extents, which only grow. So any box returned
/// is the one obb_with_axes returns, and a box not returned has a volume of at least `limit`, up to the
/// rounding of the two volume products (callers pass a limit with a margin above what they compare with).
[[nodiscard]] std::optional<Obb> obb_with_axes_below(std::span<const Sphere> spheres, const Mat3& rotation,
                                                     double limit);

/// Volume of the smallest box with axes `rotation` around the proxy's spheres (equal to obb_with_axes'
/// volume on the full set, up to rounding).
[[nodiscard]] double proxy_obb_volume(const SphereProxy& proxy, const Mat3& rotation);

/// Deterministic local search (pattern search over small rotations about the frame's own axes, with
/// halving step) that lowers proxy_obb_volume. Returns the improved frame; never a worse one.
[[nodiscard]] Mat3 refine_frame(const SphereProxy& proxy, const Mat3& rotation);

}  // namespace hbvh::detail
