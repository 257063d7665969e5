// SPDX-License-Identifier: MIT
// Exact overlap tests for every pair of BV kinds, plus the distance kernels they are built on.
#pragma once

#include "hbvh/geometry/bounding_volume.hpp"

namespace hbvh {

// Every test takes both volumes in the same frame (any frame; world frame for the types' own
// conventions). Touching counts as intersecting: the tests answer "is the closed sets' intersection
// non-empty", conservatively against rounding relative to the magnitude of the coordinates involved, not
// only to the volumes' sizes (docs/reliability.md, "Precision"): never false for touching volumes however
// far from the origin; true for separated ones only when the gap is below the slack, which is 1e-13 x
// (|t|_1 + the half extents' sum + |centres|_1) for box-box pairs (also covering the edge-edge axes of
// parallel edges, docs/queries.md) and 1e-14 x (the reach + |coordinates|_1) for every other pair. All
// are allocation-free.

/// Aabb vs Aabb: interval overlap on each world axis.
[[nodiscard]] bool overlaps(const Aabb& a, const Aabb& b);
/// Aabb vs Obb: the Aabb is treated as an Obb with identity rotation (15-axis SAT).
[[nodiscard]] bool overlaps(const Aabb& a, const Obb& b);
/// Aabb vs Sphere: closest point of the box to the centre (Ericson 5.2.5).
[[nodiscard]] bool overlaps(const Aabb& a, const Sphere& b);
/// Aabb vs Capsule: exact segment-box distance against the radius.
[[nodiscard]] bool overlaps(const Aabb& a, const Capsule& b);
/// Obb vs Obb: separating-axis test on the 15 candidate axes (Gottschalk 1996; Ericson 4.4.1).
[[nodiscard]] bool overlaps(const Obb& a, const Obb& b);
/// Obb vs Sphere: closest point of the box to the centre, in box coordinates.
[[nodiscard]] bool overlaps(const Obb& a, const Sphere& b);
/// Obb vs Capsule: exact segment-box distance (segment in box coordinates) against the radius.
[[nodiscard]] bool overlaps(const Obb& a, const Capsule& b);
/// Sphere vs Sphere: centre distance against the sum of radii.
[[nodiscard]] bool overlaps(const Sphere& a, const Sphere& b);
/// Sphere vs Capsule: point-segment distance against the sum of radii.
[[nodiscard]] bool overlaps(const Sphere& a, const Capsule& b);
/// Capsule vs Capsule: segment-segment distance against the sum of radii (robust for parallel and
/// zero-length segments).
[[nodiscard]] bool overlaps(const Capsule& a, const Capsule& b);

/// Mirror images of the ten tests above, so that every ordered pair of kinds has an overload.
[[nodiscard]] inline bool overlaps(const Obb& a, const Aabb& b) { return overlaps(b, a); }
[[nodiscard]] inline bool overlaps(const Sphere& a, const Aabb& b) { return overlaps(b, a); }
[[nodiscard]] inline bool overlaps(const Capsule& a, const Aabb& b) { return overlaps(b, a); }
[[nodiscard]] inline bool overlaps(const Sphere& a, const Obb& b) { return overlaps(b, a); }
[[nodiscard]] inline bool overlaps(const Capsule& a, const Obb& b) { return overlaps(b, a); }
[[nodiscard]] inline bool overlaps(const Capsule& a, const Sphere& b) { return overlaps(b, a); }

/// Any pair of bounding volumes (both in the same frame), dispatched once with std::visit.
[[nodiscard]] bool overlaps(const BoundingVolume& a, const BoundingVolume& b);

/// Conservative box-box test for traversals: the separating-axis test on the six face normals only
/// (the nine edge-edge axes are skipped), with a slack of 1e-12 of (|t|_1 + the half extents' sums +
/// `coordinates`) so that rounding never separates touching boxes. Never false when overlaps() of the two
/// boxes is true, given `coordinates` >= the L1 magnitudes of the coordinates the boxes and t were computed
/// from (both centres in the frame of the exact test, and the translation of any motion applied); may be
/// true for separated boxes (only an edge-edge axis separates them). Box a is [-ea, ea] in its own
/// frame; box b has half extents eb, axes R's columns (R(i, j) = A_i . B_j) and centre t in a's frame.
[[nodiscard]] bool boxes_may_overlap(const Vec3& ea, const Vec3& eb, const Mat3& r, const Vec3& t,
                                     double coordinates);

/// Squared distance between the segments p0-p1 and q0-q1 (any frame). Zero-length segments are points;
/// parallel segments are handled exactly (the minimum over endpoint distances joins the line solution).
[[nodiscard]] double segment_segment_squared_distance(const Vec3& p0, const Vec3& p1, const Vec3& q0,
                                                      const Vec3& q1);
/// Squared distance between the segment p0-p1 and the box [-half_extents, half_extents], both given in
/// the box's own frame. Exact: minimises the convex, piecewise-quadratic squared distance along the
/// segment by bracketing the sign change of its (monotone, piecewise-linear) derivative.
[[nodiscard]] double segment_box_squared_distance(const Vec3& p0, const Vec3& p1, const Vec3& half_extents);

}  // namespace hbvh
