// SPDX-License-Identifier: MIT
// Obb: an oriented box, the survey's workhorse.
#pragma once

#include "hbvh/geometry/aabb.hpp"

namespace hbvh {

/// Oriented box: world = rotation * local + center, local in [-half_extents, half_extents].
/// rotation's columns are the box axes in world space; it must be a proper rotation.
struct Obb {
    Vec3 center = Vec3::Zero();
    Mat3 rotation = Mat3::Identity();
    Vec3 half_extents = Vec3::Zero();

    [[nodiscard]] double volume() const { return 8.0 * half_extents.prod(); }
    /// True when every point of `s` is inside, allowing `tolerance` (absolute length).
    [[nodiscard]] bool contains(const Sphere& s, double tolerance = 0.0) const {
        const Vec3 local = rotation.transpose() * (s.center - center);
        return (local.cwiseAbs().array() + s.radius <= half_extents.array() + tolerance).all();
    }
    [[nodiscard]] Obb transformed(const RigidTransform& t) const {
        return {t.apply(center), t.rotation * rotation, half_extents};
    }
    /// World position of corner i (bit k of i picks the sign along axis k).
    [[nodiscard]] Vec3 corner(int i) const {
        Vec3 local(i & 1 ? half_extents.x() : -half_extents.x(), i & 2 ? half_extents.y() : -half_extents.y(),
                   i & 4 ? half_extents.z() : -half_extents.z());
        return rotation * local + center;
    }
    /// The same box as an Obb with identity rotation.
    [[nodiscard]] static Obb from_aabb(const Aabb& box) { return {box.center(), Mat3::Identity(), box.half_extents()}; }
};

}  // namespace hbvh
