// SPDX-License-Identifier: MIT
// BoundingVolume: the closed set of BV kinds, and the operations every kind supports.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>
#include <variant>
#include <vector>

#include "hbvh/geometry/aabb.hpp"
#include "hbvh/geometry/capsule.hpp"
#include "hbvh/geometry/obb.hpp"
#include "hbvh/geometry/sphere.hpp"

namespace hbvh {

/// Bounding volume of one node. The set of kinds is closed, so a variant fits better than a hierarchy.
/// The index order matches BvType.
using BoundingVolume = std::variant<Aabb, Obb, Sphere, Capsule>;

/// Lambdas joined into one visitor, for std::visit over a BoundingVolume with one lambda per kind.
template <class... Ts>
struct Overloaded : Ts... {
    using Ts::operator()...;
};
template <class... Ts>
Overloaded(Ts...) -> Overloaded<Ts...>;

/// The kind of a BoundingVolume, in variant order.
enum class BvType : std::uint8_t { aabb = 0, obb = 1, sphere = 2, capsule = 3 };
inline constexpr std::size_t bv_type_count = 4;
inline constexpr std::array<BvType, bv_type_count> all_bv_types{BvType::aabb, BvType::obb, BvType::sphere,
                                                                  BvType::capsule};

[[nodiscard]] inline BvType type_of(const BoundingVolume& bv) { return static_cast<BvType>(bv.index()); }
/// "aabb", "obb", "sphere" or "capsule".
[[nodiscard]] std::string_view to_string(BvType type);
/// Inverse of to_string; nullopt for an unknown name.
[[nodiscard]] std::optional<BvType> parse_bv_type(std::string_view name);

/// Volume of the solid (cubic units).
[[nodiscard]] double volume(const BoundingVolume& bv);
/// Area of the solid's surface (square units).
[[nodiscard]] double surface_area(const BoundingVolume& bv);
/// The solid's width averaged over all directions (its extent along a random axis): for a box (a+b+c)/2
/// with full edges a, b, c; for a sphere its diameter; for a capsule 2r + L/2.
[[nodiscard]] double mean_width(const BoundingVolume& bv);
/// The volume of the Minkowski sum of the solid with a copy of itself turned at random, averaged over the
/// turns: 2V + S w (the mixed-volume terms of the sum average to S w / 2 each; a ball of radius r gives
/// the ball of radius 2r). It is what the chance that two similar nodes meet grows with, and unlike V it
/// does not vanish for a flat box (docs/metrics.md, "Calibrated cost").
[[nodiscard]] double self_minkowski_volume(const BoundingVolume& bv);
/// The BV moved rigidly. An Aabb under a rotation becomes an Obb, so the result is exact.
[[nodiscard]] BoundingVolume transformed(const BoundingVolume& bv, const RigidTransform& t);
/// True when every point of `s` lies in `bv`, allowing `tolerance` (absolute length).
[[nodiscard]] bool contains(const BoundingVolume& bv, const Sphere& s, double tolerance = 0.0);
/// How far `s` reaches beyond `bv`: the largest distance by which a point of `s` lies outside one of the
/// volume's faces (boxes) or outside its round surface (spheres, capsules); <= 0 when `s` is inside.
/// contains(bv, s, tolerance) is protrusion(bv, s) <= tolerance, up to rounding.
[[nodiscard]] double protrusion(const BoundingVolume& bv, const Sphere& s);
/// protrusion() for one kind, for loops that dispatch on the kind once and not per sphere (the containment check).
[[nodiscard]] inline double protrusion(const Aabb& box, const Sphere& s) {
    const Vec3 below = box.min - s.center, above = s.center - box.max;
    return below.cwiseMax(above).maxCoeff() + s.radius;
}
[[nodiscard]] inline double protrusion(const Obb& box, const Sphere& s) {
    const Vec3 local = box.rotation.transpose() * (s.center - box.center);
    return (local.cwiseAbs() - box.half_extents).maxCoeff() + s.radius;
}
[[nodiscard]] inline double protrusion(const Sphere& sphere, const Sphere& s) {
    return (s.center - sphere.center).norm() + s.radius - sphere.radius;
}
[[nodiscard]] inline double protrusion(const Capsule& capsule, const Sphere& s) {
    return (s.center - capsule.closest_axis_point(s.center)).norm() + s.radius - capsule.radius;
}
/// Smallest world axis-aligned box around the BV (exact for every kind).
[[nodiscard]] Aabb world_aabb(const BoundingVolume& bv);
/// A length scale of the BV (half the diagonal of its world AABB), used to make tolerances relative.
[[nodiscard]] double size_scale(const BoundingVolume& bv);

/// The generating spheres of a BV: a finite set of spheres whose convex hull is the BV.
/// Box -> its 8 corners as radius-0 spheres; sphere -> itself; capsule -> its two end spheres.
/// Because every BV kind is convex, a convex BV contains the BV iff it contains these spheres.
void append_generating_spheres(const BoundingVolume& bv, std::vector<Sphere>& out);
/// How many spheres append_generating_spheres appends for `bv` (8, 8, 1, 2 by kind): to size a buffer first.
[[nodiscard]] std::size_t generating_sphere_count(const BoundingVolume& bv);
[[nodiscard]] std::vector<Sphere> generating_spheres(const BoundingVolume& bv);

}  // namespace hbvh
