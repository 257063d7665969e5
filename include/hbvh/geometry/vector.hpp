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

namespace detail {
/// The length of `v`: the plain norm where its square neither overflows nor underflows (the same bits as always),
/// else Eigen's stableNorm, which scales before it squares. Parts of 1e160 or 1e-300 are as valid a direction or
/// quaternion as parts of 1, and the plain norm made them infinite or 0 (divided by, every part became 0 or NaN).
template <class Vector>
[[nodiscard]] double length_of(const Vector& v) {
    const double plain = v.norm();
    return std::isfinite(plain) && plain > 1e-150 ? plain : v.stableNorm();
}
}  // namespace detail

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
        // Scaled by its largest part first: components of 1e300 or 1e-300 too, and of 1e308, whose length
        // (2e308) no double holds.
        const Eigen::Vector4d parts(x, y, z, w);
        const double largest = parts.cwiseAbs().maxCoeff();
        if (!(largest > 0.0) || !std::isfinite(largest))
            return {Mat3::Constant(std::numeric_limits<double>::quiet_NaN()), translation};
        const Eigen::Vector4d scaled = parts / largest;
        return {Eigen::Quaterniond(scaled / scaled.norm()).toRotationMatrix(), translation};
    }
};

}  // namespace hbvh
