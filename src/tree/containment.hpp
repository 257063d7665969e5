// SPDX-License-Identifier: MIT
// Internal: the containment check's pieces shared by validate()'s two overloads (a Bvh's, and a QueryTree's in
// query/): which primitive below a node reaches furthest beyond it, and the words for it.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "hbvh/geometry/bounding_volume.hpp"
#include "hbvh/result.hpp"

namespace hbvh::detail {

/// The primitive that reaches furthest beyond one node's `volume`, among those that reach beyond `tolerance`
/// (containment_tolerance), ties to the lowest index: add() each primitive below the node, in any order.
class WorstReach {
public:
    WorstReach(const BoundingVolume& volume, double tolerance, std::vector<Sphere>& scratch)
        : volume_(volume), reach_(tolerance), spheres_(scratch) {}
    void add(std::uint32_t primitive, const BoundingVolume& primitive_volume) {
        spheres_.clear();
        append_generating_spheres(primitive_volume, spheres_);
        for (const Sphere& s : spheres_)
            if (const double reach = protrusion(volume_, s);
                reach > reach_ || (primitive_ && reach == reach_ && primitive < *primitive_))
                reach_ = reach, primitive_ = primitive;
    }
    /// The primitive, when one reaches beyond the tolerance.
    [[nodiscard]] const std::optional<std::uint32_t>& primitive() const { return primitive_; }
    /// How far it reaches (the tolerance while primitive() is empty).
    [[nodiscard]] double reach() const { return reach_; }

private:
    const BoundingVolume& volume_;
    double reach_;
    std::optional<std::uint32_t> primitive_;
    std::vector<Sphere>& spheres_;
};

/// "node N: its KIND does not contain primitive P (by D)", D to three significant digits.
[[nodiscard]] Error containment_error(std::uint32_t node, BvType kind, std::uint32_t primitive, double protrusion);

}  // namespace hbvh::detail
