// SPDX-License-Identifier: MIT
// Rotation parsing conventions of MJCF (MuJoCo documentation, "Frame orientations").
#include "mjcf_orientation.hpp"

#include <cmath>

namespace hbvh::detail {
namespace {

// Below this length a direction carries no information; MuJoCo uses a similar cut-off (mjMINVAL).
constexpr double tiny_length = 1e-14;
/// Below this sine between a zaxis (or fromto) direction and +-z, MuJoCo takes the direction as exactly +-z.
constexpr double mujoco_parallel_sine = 1e-7;

using detail::length_of;  // a quaternion or axis of 1e160 parts is as valid as one of 1

}  // namespace

std::optional<Mat3> rotation_from_quat(double w, double x, double y, double z) {
    Eigen::Quaterniond q(w, x, y, z);
    const double length = length_of(q.coeffs());
    if (length < tiny_length) return std::nullopt;
    q.coeffs() /= length;
    return q.toRotationMatrix();
}

std::optional<Mat3> rotation_from_axis_angle(const Vec3& axis, double angle) {
    const double length = length_of(axis);
    if (length < tiny_length) return std::nullopt;
    return Eigen::AngleAxisd(angle, axis / length).toRotationMatrix();
}

std::optional<Mat3> rotation_from_euler(const Vec3& angles, std::string_view sequence) {
    if (sequence.size() != 3) return std::nullopt;
    Mat3 rotation = Mat3::Identity();
    for (int i = 0; i < 3; ++i) {
        const char c = sequence[static_cast<std::size_t>(i)];
        Vec3 axis;
        switch (c) {
            case 'x': case 'X': axis = Vec3::UnitX(); break;
            case 'y': case 'Y': axis = Vec3::UnitY(); break;
            case 'z': case 'Z': axis = Vec3::UnitZ(); break;
            default: return std::nullopt;
        }
        const Mat3 step = Eigen::AngleAxisd(angles[i], axis).toRotationMatrix();
        // Lower case: intrinsic axes, so each new turn happens in the already-rotated frame.
        const bool intrinsic = c == 'x' || c == 'y' || c == 'z';
        rotation = intrinsic ? Mat3(rotation * step) : Mat3(step * rotation);
    }
    return rotation;
}

std::optional<Mat3> rotation_from_xy_axes(const Vec3& x, const Vec3& y) {
    const double x_length = length_of(x);
    if (x_length < tiny_length) return std::nullopt;
    const Vec3 x_unit = x / x_length;
    // Gram-Schmidt: only the part of y orthogonal to x counts, as in MuJoCo.
    const Vec3 y_orthogonal = y - x_unit.dot(y) * x_unit;
    const double y_length = length_of(y_orthogonal);
    if (y_length < tiny_length) return std::nullopt;
    Mat3 rotation;
    rotation.col(0) = x_unit;
    rotation.col(1) = y_orthogonal / y_length;
    rotation.col(2) = x_unit.cross(rotation.col(1));
    return rotation;
}

std::optional<Mat3> rotation_from_z_axis(const Vec3& z) {
    const double length = length_of(z);
    if (length < tiny_length) return std::nullopt;
    const Vec3 direction = z / length;
    const Vec3 axis = Vec3::UnitZ().cross(direction);
    const double sine = axis.norm();
    if (sine < mujoco_parallel_sine) {
        // Parallel to z: identity, or a half turn about x for -z. MuJoCo 2.2.2 counts a direction as parallel
        // up to a sine of 1e-7 (measured with mj_loadXML on zaxis and fromto; tests/io/data/mjcf_orientations.xml
        // holds a box on each side of it): near -z the turn's axis is ill-conditioned, and about any other axis
        // a box with unequal x and y sizes would come out turned by up to 90 degrees about z.
        if (direction.z() >= 0.0) return Mat3::Identity();
        return Mat3(Vec3(1.0, -1.0, -1.0).asDiagonal());
    }
    return Eigen::AngleAxisd(std::atan2(sine, direction.z()), axis / sine).toRotationMatrix();
}

}  // namespace hbvh::detail
