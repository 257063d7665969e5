// SPDX-License-Identifier: MIT
// The interface hbvh_peers drives Bullet and FCL through, and the primitive shape both are built from.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <span>
#include <string_view>
#include <utility>
#include <vector>

#include "hbvh/geometry/primitive.hpp"

namespace hbvh::peers {

/// Overlapping pairs (primitive of a, primitive of b), input order indices.
using PairList = std::vector<std::pair<std::uint32_t, std::uint32_t>>;

/// A primitive as the engines see it: a shape centred at the origin of a local frame, placed by `frame`.
/// Boxes are given by half extents, capsules lie along the local z axis (both engines' convention).
struct LocalShape {
    enum class Kind : std::uint8_t { box, sphere, capsule };
    Kind kind = Kind::sphere;
    RigidTransform frame;
    Vec3 half_extents = Vec3::Zero();  ///< box
    double radius = 0.0;               ///< sphere, capsule
    double length = 0.0;               ///< capsule: distance between the end-sphere centres
};

/// Converts one primitive. An Aabb becomes an unrotated box; a zero-length capsule a sphere.
[[nodiscard]] LocalShape to_local_shape(const BoundingVolume& volume);

/// One engine holding two copies of the same object: copy a at the identity, copy b posed.
class Peer {
public:
    virtual ~Peer() = default;
    /// Moves copy b. Separate from collide() because for FCL it is real work (one update per primitive).
    virtual void set_pose(const RigidTransform& pose_b) = 0;
    /// All overlapping primitive pairs (a, b) at the current pose, sorted, without duplicates.
    virtual void collide(PairList& pairs) = 0;
    /// Eq. 2 of the engine's own tree over one copy (model frame): sum over inner nodes of 2 x AABB volume.
    [[nodiscard]] virtual double cost() const = 0;
    /// Seconds the constructor spent building one copy's structure (shapes and tree), without engine
    /// set-up that a program does once (Bullet's collision configuration and dispatcher).
    [[nodiscard]] virtual double build_seconds() const = 0;
};

/// Bullet: one btCompoundShape (dynamic AABB tree on, margins 0), compound-vs-compound through the dispatcher.
[[nodiscard]] std::unique_ptr<Peer> make_bullet_peer(std::span<const Primitive> primitives);
/// FCL: one DynamicAABBTreeCollisionManager per copy, manager-vs-manager with fcl::collide per candidate.
[[nodiscard]] std::unique_ptr<Peer> make_fcl_peer(std::span<const Primitive> primitives);

}  // namespace hbvh::peers
