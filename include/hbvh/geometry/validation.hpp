// SPDX-License-Identifier: MIT
// validation: the checks that stand between geometry from a program and the builders and queries.
//
// Every conservative test in hbvh assumes finite numbers, non-negative sizes and proper rotations; a NaN
// centre makes every comparison false and silently prunes a subtree. So build(), QueryTree and collide()
// refuse such input with an Error instead of computing on it (docs/bad-input.md).
#pragma once

#include <span>
#include <string>

#include "hbvh/geometry/primitive.hpp"
#include "hbvh/result.hpp"

namespace hbvh {

/// Largest |R^T R - I| entry (and |det R - 1|) accepted for a rotation: a few thousand ulps, far more than
/// composing a handful of rotations or normalising a quaternion loses, far less than any real shear.
inline constexpr double rotation_tolerance = 1e-9;

/// Empty when `rotation` is a proper rotation within rotation_tolerance; otherwise the problem in words.
[[nodiscard]] std::string rotation_problem(const Mat3& rotation);
/// The rotation nearest `m` in the Frobenius norm: the orthogonal factor U V^T of its polar decomposition (from
/// the SVD m = U S V^T). For a matrix meant as a rotation but rounded (a file's few digits, float32): with
/// det(m) > 0 and S near 1, U V^T is a proper rotation. Callers decide first how far from one `m` may be.
[[nodiscard]] Mat3 nearest_rotation(const Mat3& m);
/// `rotation` itself when it is orthonormal to a few units in the last place (|R^T R - I| <= 2e-15, what a
/// normalised quaternion's matrix or a few products of rotations give), else nearest_rotation(rotation). For a
/// rotation accepted within rotation_tolerance: R^T is then its inverse to rounding, so that code moving points
/// with R and back with R^T stays consistent (a 4e-10 error moved geometry 1e6 from the origin by 4e-4).
[[nodiscard]] Mat3 exact_rotation(const Mat3& rotation);
/// Empty when `volume` is usable geometry; otherwise the problem in words ("radius -1 is negative", ...).
/// Refused: non-finite numbers (also derived ones: a box's extent, a capsule's length), sizes < 0 and
/// subnormal sizes (they vanish in the first product), rotations that are no proper rotation.
/// Zero sizes are fine: a flat box, a point sphere, a capsule with p0 == p1 (a sphere).
[[nodiscard]] std::string volume_problem(const BoundingVolume& volume);
/// Ok, or an Error naming the first bad primitive: "primitive 3 ('leg'): radius -0.5 is negative". A name
/// holding a NUL byte is refused too (no hierarchy file keeps it).
[[nodiscard]] Status validate_primitives(std::span<const Primitive> primitives);
/// validate_pose(pose) is Ok, without building a message: cheap enough to run on every query.
[[nodiscard]] bool is_rigid_motion(const RigidTransform& pose);
/// Empty, or why `pose` is no rigid motion ("translation is not finite", or rotation_problem's words), for a
/// caller that names the pose itself ("pose_a: ...", "--pose: ...").
[[nodiscard]] std::string pose_problem(const RigidTransform& pose);
/// Ok, or an Error "pose: " + pose_problem(pose).
[[nodiscard]] Status validate_pose(const RigidTransform& pose);

}  // namespace hbvh
