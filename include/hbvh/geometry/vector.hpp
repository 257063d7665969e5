// SPDX-License-Identifier: MIT
// Linear-algebra vocabulary: Eigen's fixed-size types, and the rigid transform every BV understands.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

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
};

}  // namespace hbvh
