// SPDX-License-Identifier: MIT
// Linear-algebra vocabulary: Eigen's fixed-size types, and the rigid transform every BV understands.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <limits>

namespace hbvh {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

/// A rigid motion: x -> rotation * x + translation. rotation must be a proper rotation (det +1).
struct RigidTransform {
    Mat3 rotation = Mat3::Identity();
    Vec3 translation = Vec3::Zero();

    [[nodiscard]] Vec3 apply(const Vec3& point) const { return rotation * point + translation; }
    /// The transform that undoes this one.
    [[nodiscard]] RigidTransform inverse() const {
        return {rotation.transpose(), -(rotation.transpose() * translation)};
    }
    /// (this * other)(x) = this(other(x)).
    [[nodiscard]] RigidTransform operator*(const RigidTransform& other) const {
        return {rotation * other.rotation, rotation * other.translation + translation};
    }
    [[nodiscard]] static RigidTransform identity() { return {}; }
    /// The rotation of the quaternion (w, x, y, z), normalised first so that any non-zero quaternion gives a
    /// proper rotation, then `translation`. A zero or non-finite quaternion gives a non-finite rotation,
    /// which validate_pose() and collide() refuse.
    [[nodiscard]] static RigidTransform from_quaternion(double w, double x, double y, double z,
                                                        const Vec3& translation = Vec3::Zero()) {
        const Eigen::Quaterniond q(w, x, y, z);
        // Where the plain norm's square overflows or underflows (components of 1e300 or 1e-300, which came out
        // refused as non-finite), the norm is scaled before it squares (stableNorm); elsewhere it is the plain one.
        const double plain = q.norm();
        const double norm = std::isfinite(plain) && plain > 1e-150 ? plain : q.coeffs().stableNorm();
        if (!(norm > 0.0) || !std::isfinite(norm))
            return {Mat3::Constant(std::numeric_limits<double>::quiet_NaN()), translation};
        return {Eigen::Quaterniond(q.coeffs() / norm).toRotationMatrix(), translation};
    }
};

}  // namespace hbvh
