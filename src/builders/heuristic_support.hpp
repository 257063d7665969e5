// SPDX-License-Identifier: MIT
// Internal helpers shared by the survey's heuristic builders (merge, split, OBB-tree, insertion):
// per-primitive fitting data, fitting around a set of primitives, and a geometric canonical order.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "hbvh/fit/volume_policy.hpp"
#include "hbvh/geometry/primitive.hpp"

namespace hbvh::detail {

/// Input indices sorted by the primitives' geometry alone (world-box centre, then the kind, then every
/// parameter). Builders that must not depend on input order work in this order, so every tie they break
/// "by index" is really broken by geometry; identical primitives are interchangeable, so their relative
/// order does not matter.
[[nodiscard]] std::vector<std::uint32_t> canonical_order(std::span<const Primitive> primitives);

/// The primitives of one build with what fitting needs, computed once. Builders address primitives by a
/// local index `0..size()-1`; `input_index(local)` maps back to the caller's order.
class PrimitiveSet {
public:
    /// `order[local]` is the input index of local primitive `local` (a permutation of the input).
    PrimitiveSet(std::span<const Primitive> primitives, std::vector<std::uint32_t> order, const VolumePolicy& policy);

    [[nodiscard]] std::uint32_t size() const { return static_cast<std::uint32_t>(order_.size()); }
    [[nodiscard]] std::uint32_t input_index(std::uint32_t local) const { return order_[local]; }
    [[nodiscard]] const BoundingVolume& volume_of(std::uint32_t local) const;
    /// Centre of the primitive's world box (the true centre for every symmetric kind).
    [[nodiscard]] const Vec3& centre(std::uint32_t local) const { return centres_[local]; }
    /// Generating spheres of the primitive.
    [[nodiscard]] std::span<const Sphere> spheres(std::uint32_t local) const;
    /// The primitive's own BV, weighted by the policy (its volume in Eq. 2 and Eq. 3).
    [[nodiscard]] double primitive_volume(std::uint32_t local) const { return volumes_[local]; }
    [[nodiscard]] const VolumePolicy& policy() const { return policy_; }
    [[nodiscard]] double weighted_volume(const BoundingVolume& bv) const { return policy_.weighted_volume(bv); }

    /// fit_best over the generating spheres of the primitives `locals` (any order: they are sorted first,
    /// so the result does not depend on the order of the list). Precondition: non-empty.
    [[nodiscard]] BoundingVolume fit(std::span<const std::uint32_t> locals) const;
    /// estimate_weighted_volume around the primitives `locals` (order-independent, like fit()).
    [[nodiscard]] double estimate(std::span<const std::uint32_t> locals) const;

private:
    std::span<const Primitive> primitives_;
    std::vector<std::uint32_t> order_;
    VolumePolicy policy_;
    std::vector<std::uint32_t> sphere_begin_;  ///< spheres_[sphere_begin_[i], sphere_begin_[i + 1]).
    std::vector<Sphere> spheres_;
    std::vector<Vec3> centres_;
    std::vector<double> volumes_;
};

/// The pricing fitter: the smallest weighted volume, over the allowed kinds, of a cheap enclosing BV of
/// each kind around `spheres`: the exact AABB and sphere; an OBB over the world frame, the PCA frame of
/// the sphere centres and the frames of any boxes among `hints`; a capsule on the PCA axis and on the axes
/// of any capsules among `hints`. Every candidate really encloses the spheres, so this is an upper bound
/// of fit_best, at a few microseconds instead of the hull-based fitters' milliseconds. Builders price
/// thousands of candidates with it and call fit_best only for the BVs they keep.
[[nodiscard]] double estimate_weighted_volume(std::span<const Sphere> spheres, std::span<const BoundingVolume> hints,
                                              const VolumePolicy& policy);
/// estimate_weighted_volume around the generating spheres of `volumes` (the "BV around these BVs").
[[nodiscard]] double estimate_around(std::span<const BoundingVolume> volumes, const VolumePolicy& policy);

/// The BV scaled about its centre by `factor` in every linear dimension (box half extents, radii, capsule
/// segment), used by the merge builder's enlarged-BV neighbour test.
[[nodiscard]] BoundingVolume enlarged(const BoundingVolume& bv, double factor);

}  // namespace hbvh::detail
