// SPDX-License-Identifier: MIT
// Internal: fit_best in two steps, the capsule fitter (the dearest step) last and only on request, for a caller
// that often needs no more than a lower bound of the answer (the treelet DP, docs/treelets.md, "The capsule on
// demand").
#pragma once

#include <algorithm>
#include <cstddef>
#include <optional>
#include <span>
#include <vector>

#include "fit_context.hpp"
#include "hbvh/fit/volume_policy.hpp"
#include "hbvh/geometry/bounding_volume.hpp"

namespace hbvh::detail {

/// fit_best drops exact repeats from sets larger than this first (smaller sets are fitted as they are: the check
/// would cost more than the repeats it could save).
inline constexpr std::size_t repeats_checked_above = 256;

/// `spheres` without exact repeats, first occurrences in their original order; empty when there are none to
/// drop. Repeats change no BV, but degenerate sets (10^5 copies of one sphere: a flat hull, a zero covariance)
/// sent the hull and search steps down slow paths whose cost grew with the copies.
[[nodiscard]] std::vector<Sphere> without_repeats(std::span<const Sphere> spheres);

/// What fit_best has found before its capsule step. fit_best tries AABB, OBB, sphere and capsule in that order
/// and keeps the first of the cheapest; the capsule step runs unless a lower bound of every capsule's volume
/// already reaches the best price (capsule_bound.hpp). Where it would run, the first step stops short of it,
/// with that bound recorded, and finish() runs it: the answer is then fit_best's, bit for bit.
struct FitStages {
    std::optional<FitContext> context;
    std::optional<Sphere> enclosing;  ///< fit_sphere of the spheres, once made
    std::optional<BoundingVolume> best;
    double best_cost = 0.0;
    /// The frames whose planes the capsule bound tries (the fitted boxes' first, then the world's).
    std::vector<Mat3> bound_planes;
    bool capsule_pending = false;
    /// While the capsule step is pending: the capsule's weight times the bound of its volume, less a
    /// millionth (so that rounding cannot put it above a capsule the fitter finds).
    double capsule_floor = 0.0;

    /// fit_best's weighted measure of its answer once nothing is pending, else a lower bound of it.
    [[nodiscard]] double lower_bound() const { return capsule_pending ? std::min(best_cost, capsule_floor) : best_cost; }

    /// Runs the pending capsule step, if any, on the spheres and policy start_fit had; `best` is then fit_best's
    /// answer.
    void finish(std::span<const Sphere> spheres, const VolumePolicy& policy);
};

/// Every step of fit_best(spheres, policy, hint_axes) but a capsule step that could still win (after the repeats
/// check: fit_best calls this with the spheres it fits).
[[nodiscard]] FitStages start_fit(std::span<const Sphere> spheres, const VolumePolicy& policy,
                                  std::span<const Mat3> hint_axes);

/// start_fit over spheres it keeps (those fit_best would fit: without exact repeats above repeats_checked_above),
/// for a caller that may run the capsule step later, when the spheres it was given are gone.
struct OwnedFit {
    std::vector<Sphere> spheres;
    FitStages stages;

    /// Runs the pending capsule step, if any (FitStages::finish on the kept spheres).
    void finish(const VolumePolicy& policy) { stages.finish(spheres, policy); }
};
[[nodiscard]] OwnedFit start_owned_fit(std::vector<Sphere> spheres, const VolumePolicy& policy,
                                       std::span<const Mat3> hint_axes);

}  // namespace hbvh::detail
