// SPDX-License-Identifier: MIT
// Fitting: the smallest BV of each kind around a set of spheres.
//
// Every primitive reduces to its generating spheres (geometry/bounding_volume.hpp), and every BV kind is
// convex, so containing those spheres is the same as containing the primitives. One input type serves
// every fitter, for leaves and inner nodes alike.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "hbvh/fit/volume_policy.hpp"
#include "hbvh/geometry/bounding_volume.hpp"
#include "hbvh/geometry/primitive.hpp"

namespace hbvh {

/// Exact smallest axis-aligned box. Precondition: spheres non-empty.
[[nodiscard]] Aabb fit_aabb(std::span<const Sphere> spheres);
/// Exact minimum enclosing sphere of spheres. Precondition: spheres non-empty.
[[nodiscard]] Sphere fit_sphere(std::span<const Sphere> spheres);
/// Gottschalk's covariance OBB: axes from the covariance of the convex hull's points (the survey's method).
[[nodiscard]] Obb fit_obb_covariance(std::span<const Sphere> spheres);
/// The smallest of several candidate orientations (covariance, world axes, the inputs' own axes,
/// DiTO-style axes); never larger than fit_obb_covariance nor the AABB.
/// `hint_axes` are extra orientations to try, e.g. the axes of covered boxes.
[[nodiscard]] Obb fit_obb(std::span<const Sphere> spheres, std::span<const Mat3> hint_axes = {});
/// Smallest capsule over candidate axes (PCA and as for the OBB): radius and length as small as can be
/// while every sphere is inside.
[[nodiscard]] Capsule fit_capsule(std::span<const Sphere> spheres, std::span<const Mat3> hint_axes = {});
/// The fitter for one kind.
[[nodiscard]] BoundingVolume fit(BvType type, std::span<const Sphere> spheres, std::span<const Mat3> hint_axes = {});
/// The allowed kind with the smallest weighted volume. A policy that allows no kind is read as allowing every
/// kind (a volume must enclose the spheres; that one was an empty box at the origin); builders refuse such a
/// policy first (validate_policy).
[[nodiscard]] BoundingVolume fit_best(std::span<const Sphere> spheres, const VolumePolicy& policy,
                                      std::span<const Mat3> hint_axes = {});

/// Convenience: generating spheres and box axes of a set of primitives, ready for the fitters.
/// add() is O(max_hint_axes) = O(1) per volume, so gathering n primitives is O(n).
struct FitInput {
    /// At most this many hint axes are kept: the first distinct orientations in the order added. The
    /// fitters rank every hint over the hull points and keep the best 8 (O(hints x hull) per fit), and the
    /// orientations of a few of many differently oriented boxes rarely shape a box around all of them.
    /// 64 is above the distinct orientations of every bundled model, so their fits keep every hint.
    static constexpr std::size_t max_hint_axes = 64;

    std::vector<Sphere> spheres;
    /// Rotations of the covered OBBs, first occurrences in order, deduplicated loosely (two rotations whose
    /// entries all differ by less than 1e-9 count as one), at most max_hint_axes.
    std::vector<Mat3> hint_axes;
    void add(const BoundingVolume& bv);
};

}  // namespace hbvh
