// SPDX-License-Identifier: MIT
// Private: MJCF's ways of writing a rotation, each turned into a rotation matrix with MuJoCo's conventions.
#pragma once

#include <optional>
#include <string_view>

#include "hbvh/geometry/vector.hpp"

namespace hbvh::detail {

/// Unit quaternion (w, x, y, z) as a matrix; nullopt for the zero quaternion.
[[nodiscard]] std::optional<Mat3> rotation_from_quat(double w, double x, double y, double z);
/// Rotation by `angle` radians about `axis` (any length); nullopt for a zero axis.
[[nodiscard]] std::optional<Mat3> rotation_from_axis_angle(const Vec3& axis, double angle);
/// Euler angles (radians) applied in `sequence` (3 of x y z X Y Z): lower case rotates about the moving frame
/// (post-multiply), upper case about the fixed frame (pre-multiply). nullopt for a bad sequence.
[[nodiscard]] std::optional<Mat3> rotation_from_euler(const Vec3& angles, std::string_view sequence);
/// Frame whose x axis is along `x` and whose y axis is `y` made orthogonal to it; nullopt when degenerate.
[[nodiscard]] std::optional<Mat3> rotation_from_xy_axes(const Vec3& x, const Vec3& y);
/// The minimal rotation taking +z to the direction of `z`; a half turn about x for -z (MuJoCo's choice, so that
/// imported frames match the oracle exactly). nullopt for a zero vector.
[[nodiscard]] std::optional<Mat3> rotation_from_z_axis(const Vec3& z);

}  // namespace hbvh::detail
