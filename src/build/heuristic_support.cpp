// SPDX-License-Identifier: MIT
// Shared fitting data and the canonical primitive order for the heuristic builders.
#include "heuristic_support.hpp"

#include <algorithm>
#include <array>
#include <numeric>
#include <utility>

#include "hbvh/assert.hpp"
#include "hbvh/fit/fit.hpp"

namespace hbvh::detail {
namespace {

// Every number that pins down a BV, world-box centre first so the order is also roughly spatial.
using Key = std::array<double, 22>;

Key key_of(const BoundingVolume& bv) {
    Key key{};
    key.fill(0.0);
    const Vec3 centre = world_aabb(bv).center();
    key[0] = centre.x();
    key[1] = centre.y();
    key[2] = centre.z();
    key[3] = static_cast<double>(bv.index());
    std::size_t k = 4;
    const auto put = [&](const auto& matrix) {
        for (Eigen::Index i = 0; i < matrix.size(); ++i) key[k++] = matrix.data()[i];
    };
    std::visit(
        [&](const auto& v) {
            using T = std::decay_t<decltype(v)>;
            if constexpr (std::is_same_v<T, Aabb>) {
                put(v.min);
                put(v.max);
            } else if constexpr (std::is_same_v<T, Obb>) {
                put(v.half_extents);
                put(v.rotation);
                put(v.center);
            } else if constexpr (std::is_same_v<T, Sphere>) {
                put(v.center);
                key[k++] = v.radius;
            } else {
                put(v.p0);
                put(v.p1);
                key[k++] = v.radius;
            }
        },
        bv);
    return key;
}

// At most this many covered boxes lend their axes to fit_obb: enough to catch the artist's dominant
// orientations, while a node over thousands of randomly rotated boxes does not try thousands of frames.
constexpr std::size_t max_hint_boxes = 8;

void add_hint(std::vector<Mat3>& hints, const Mat3& rotation) {
    for (const Mat3& axes : hints)
        if ((axes - rotation).cwiseAbs().maxCoeff() < 1e-9) return;
    hints.push_back(rotation);
}

}  // namespace

std::vector<std::uint32_t> canonical_order(std::span<const Primitive> primitives) {
    std::vector<Key> keys;
    keys.reserve(primitives.size());
    for (const Primitive& p : primitives) keys.push_back(key_of(p.volume));
    std::vector<std::uint32_t> order(primitives.size());
    std::iota(order.begin(), order.end(), 0u);
    // Stable: equal keys are identical geometry, whose order cannot change any result.
    std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return keys[a] < keys[b]; });
    return order;
}

PrimitiveSet::PrimitiveSet(std::span<const Primitive> primitives, std::vector<std::uint32_t> order,
                           const VolumePolicy& policy)
    : primitives_(primitives), order_(std::move(order)), policy_(policy) {
    HBVH_ASSERT(order_.size() == primitives.size());
    sphere_begin_.reserve(order_.size() + 1);
    sphere_begin_.push_back(0);
    for (const std::uint32_t input : order_) {
        const BoundingVolume& bv = primitives_[input].volume;
        append_generating_spheres(bv, spheres_);
        sphere_begin_.push_back(static_cast<std::uint32_t>(spheres_.size()));
        centres_.push_back(world_aabb(bv).center());
        volumes_.push_back(policy_.weighted_volume(bv));
    }
}

const BoundingVolume& PrimitiveSet::volume_of(std::uint32_t local) const { return primitives_[order_[local]].volume; }

std::span<const Sphere> PrimitiveSet::spheres(std::uint32_t local) const {
    return {spheres_.data() + sphere_begin_[local], spheres_.data() + sphere_begin_[local + 1]};
}

BoundingVolume PrimitiveSet::fit(std::span<const std::uint32_t> locals) const {
    HBVH_ASSERT(!locals.empty());
    std::vector<std::uint32_t> sorted(locals.begin(), locals.end());
    std::sort(sorted.begin(), sorted.end());
    std::vector<Sphere> spheres;
    std::vector<std::pair<double, std::uint32_t>> boxes;  // (-volume, local): largest boxes first
    for (const std::uint32_t local : sorted) {
        const std::span<const Sphere> own = this->spheres(local);
        spheres.insert(spheres.end(), own.begin(), own.end());
        if (std::holds_alternative<Obb>(volume_of(local))) boxes.emplace_back(-volume(volume_of(local)), local);
    }
    const std::size_t keep = std::min(boxes.size(), max_hint_boxes);
    std::partial_sort(boxes.begin(), boxes.begin() + static_cast<std::ptrdiff_t>(keep), boxes.end());
    std::vector<Mat3> hints;
    for (std::size_t i = 0; i < keep; ++i) add_hint(hints, std::get<Obb>(volume_of(boxes[i].second)).rotation);
    return fit_best(spheres, policy_, hints);
}

BoundingVolume fit_around(std::span<const BoundingVolume> volumes, const VolumePolicy& policy) {
    std::vector<Sphere> spheres;
    std::vector<Mat3> hints;
    for (const BoundingVolume& bv : volumes) {
        append_generating_spheres(bv, spheres);
        if (const Obb* box = std::get_if<Obb>(&bv)) add_hint(hints, box->rotation);
    }
    return fit_best(spheres, policy, hints);
}

BoundingVolume enlarged(const BoundingVolume& bv, double factor) {
    return std::visit(
        [factor](const auto& v) -> BoundingVolume {
            using T = std::decay_t<decltype(v)>;
            if constexpr (std::is_same_v<T, Aabb>) {
                const Vec3 c = v.center();
                const Vec3 h = factor * v.half_extents();
                return Aabb{c - h, c + h};
            } else if constexpr (std::is_same_v<T, Obb>) {
                return Obb{v.center, v.rotation, factor * v.half_extents};
            } else if constexpr (std::is_same_v<T, Sphere>) {
                return Sphere{v.center, factor * v.radius};
            } else {
                const Vec3 c = v.center();
                return Capsule{c + factor * (v.p0 - c), c + factor * (v.p1 - c), factor * v.radius};
            }
        },
        bv);
}

}  // namespace hbvh::detail
