// SPDX-License-Identifier: MIT
#include "xml_fields.hpp"

#include <array>
#include <cmath>
#include <limits>
#include <optional>

namespace hbvh::detail {
namespace {

/// `value` moved by `steps` units in the last place (towards +infinity for positive steps).
double stepped(double value, int steps) {
    const double towards = steps > 0 ? std::numeric_limits<double>::infinity() : -std::numeric_limits<double>::infinity();
    for (int i = 0; i < std::abs(steps); ++i) value = std::nextafter(value, towards);
    return value;
}

/// Nearest first: 0, -1, +1, -2, +2, ... up to +-reach units in the last place.
template <int Reach>
constexpr std::array<int, 2 * Reach + 1> nearest_steps() {
    std::array<int, 2 * Reach + 1> steps{};
    for (int k = 1; k <= Reach; ++k) steps[2 * k - 1] = -k, steps[2 * k] = k;
    return steps;
}

/// A centre coordinate near `centre` whose distances `half` below and above round to `low` and `high`.
std::optional<double> centre_between(double centre, double half, double low, double high) {
    for (const int step : nearest_steps<3>()) {
        const double candidate = stepped(centre, step);
        if (candidate - half == low && candidate + half == high) return candidate;
    }
    return std::nullopt;
}

}  // namespace

AabbFields exact_aabb_fields(const Aabb& box) {
    const AabbFields nearest{box.center(), box.max - box.min};
    AabbFields fields = nearest;
    for (int axis = 0; axis < 3; ++axis) {
        for (const int step : nearest_steps<3>()) {
            const double extent = stepped(nearest.extents[axis], step);
            if (!(extent >= 0.0)) continue;
            if (const std::optional<double> centre =
                    centre_between(nearest.centre[axis], 0.5 * extent, box.min[axis], box.max[axis])) {
                fields.centre[axis] = *centre;
                fields.extents[axis] = extent;
                break;
            }
        }
    }
    return fields;
}

CapsuleFields exact_capsule_fields(const Capsule& capsule) {
    const CapsuleFields nearest{capsule.center(), capsule.direction(), capsule.length()};
    for (const int step : nearest_steps<4>()) {
        CapsuleFields fields = nearest;
        fields.length = stepped(nearest.length, step);
        if (!(fields.length >= 0.0)) continue;
        const Capsule made = capsule_from_fields(Vec3::Zero(), fields.direction, fields.length, capsule.radius);
        const Vec3 half_axis = made.p1;  // the reader's half axis, exactly as it computes it
        bool all = true;
        for (int axis = 0; axis < 3 && all; ++axis) {
            const std::optional<double> centre =
                centre_between(nearest.centre[axis], half_axis[axis], capsule.p0[axis], capsule.p1[axis]);
            if (centre) fields.centre[axis] = *centre;
            all = centre.has_value();
        }
        if (all) return fields;
    }
    return nearest;
}

}  // namespace hbvh::detail
