// SPDX-License-Identifier: MIT
// Shared fitting data and the canonical primitive order for the heuristic builders.
#include "heuristic_support.hpp"

#include <algorithm>
#include <array>
#include <limits>
#include <numeric>
#include <utility>

#include <Eigen/Eigenvalues>

#include "hbvh/assert.hpp"
#include "hbvh/fit/fit.hpp"
#include "../memory/huge_pages.hpp"
#include "../memory/thread_scratch.hpp"
#include "../fit/sphere_extents.hpp"
#include "../fit/sphere_floor.hpp"

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
    // Every array at its final size before the first write: no regrowth, and large inputs on huge pages.
    std::size_t sphere_count = 0;
    for (const Primitive& p : primitives) sphere_count += generating_sphere_count(p.volume);
    reserve_on_huge_pages(spheres_, sphere_count);
    reserve_on_huge_pages(sphere_begin_, order_.size() + 1);
    reserve_on_huge_pages(centres_, order_.size());
    reserve_on_huge_pages(volumes_, order_.size());
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

double PrimitiveSet::estimate(std::span<const std::uint32_t> locals) const {
    HBVH_ASSERT(!locals.empty());
    // Per thread and kept (memory/thread_scratch.hpp): the builders call this for every candidate group, and fresh
    // arrays were a tenth of auto's allocations (heaptrack on the ANYmal).
    thread_local std::vector<std::uint32_t> sorted;
    thread_local std::vector<Sphere> spheres;
    thread_local std::vector<BoundingVolume> hints;
    const ReleaseIfLarge release(sorted, spheres, hints);
    sorted.assign(locals.begin(), locals.end());
    std::sort(sorted.begin(), sorted.end());
    spheres.clear();
    hints.clear();
    for (const std::uint32_t local : sorted) {
        const std::span<const Sphere> own = this->spheres(local);
        spheres.insert(spheres.end(), own.begin(), own.end());
        const BoundingVolume& bv = volume_of(local);
        if (!std::holds_alternative<Aabb>(bv) && !std::holds_alternative<Sphere>(bv) && hints.size() < max_hint_boxes)
            hints.push_back(bv);
    }
    return estimate_weighted_volume(spheres, hints, policy_);
}

namespace {

// Box around the spheres in the frame `rotation` (columns = axes), given in that frame: its volume and the
// calibrated measure are those of the OBB, both being invariant under rotation.
Aabb box_in(std::span<const Sphere> spheres, const Mat3& rotation) {
    const SphereExtents extents = sphere_extents(spheres, rotation);
    return {extents.low, extents.high};
}

// Capsule on the line through `origin` along unit `axis`: the radius covers every sphere's distance from
// the line, the segment spans the centres' projections, so every sphere is inside.
Capsule capsule_around_line(std::span<const Sphere> spheres, const Vec3& origin, const Vec3& axis) {
    const LineReach reach = line_reach(spheres, origin, axis);
    return Capsule{origin + reach.t_min * axis, origin + reach.t_max * axis, reach.radius};
}

}  // namespace

double estimate_weighted_volume(std::span<const Sphere> spheres, std::span<const BoundingVolume> hints,
                                const VolumePolicy& policy) {
    HBVH_ASSERT(!spheres.empty());
    double best = std::numeric_limits<double>::infinity();
    // Candidates are measured as the policy measures a node (volume, or the calibrated objective's measure).
    const auto measure = [&](const BoundingVolume& candidate) { return policy.unweighted_measure(candidate); };
    const auto consider = [&](BvType type, double v) { best = std::min(best, policy.weight_of(type) * v); };
    // The widest extent seen along any axis tried: the enclosing sphere is at least that wide.
    const Aabb world_box = fit_aabb(spheres);
    double widest = (world_box.max - world_box.min).maxCoeff();
    if (policy.is_allowed(BvType::aabb)) consider(BvType::aabb, measure(world_box));

    if (policy.is_allowed(BvType::obb) || policy.is_allowed(BvType::capsule)) {
        // Principal axes of the centres (weighted equally), as Gottschalk's covariance fit but without a hull.
        Vec3 mean = Vec3::Zero();
        for (const Sphere& s : spheres) mean += s.center;
        mean /= static_cast<double>(spheres.size());
        Mat3 covariance = Mat3::Zero();
        for (const Sphere& s : spheres) covariance += (s.center - mean) * (s.center - mean).transpose();
        const Eigen::SelfAdjointEigenSolver<Mat3> eigen(covariance);
        const Mat3 principal = eigen.eigenvectors();  // columns ascending by eigenvalue; last = main axis
        if (policy.is_allowed(BvType::obb)) {
            const Aabb principal_box = box_in(spheres, principal);
            widest = std::max(widest, (principal_box.max - principal_box.min).maxCoeff());
            double v = std::min(measure(box_in(spheres, Mat3::Identity())), measure(principal_box));
            for (const BoundingVolume& hint : hints)
                if (const Obb* box = std::get_if<Obb>(&hint)) v = std::min(v, measure(box_in(spheres, box->rotation)));
            consider(BvType::obb, v);
        }
        if (policy.is_allowed(BvType::capsule)) {
            double v = measure(capsule_around_line(spheres, mean, principal.col(2)));
            for (const BoundingVolume& hint : hints)
                if (const Capsule* capsule = std::get_if<Capsule>(&hint))
                    v = std::min(v, measure(capsule_around_line(spheres, capsule->center(), capsule->direction())));
            consider(BvType::capsule, v);
        }
    }

    // The exact enclosing sphere (CGAL) last, and only where it can still be the least: where even the least
    // sphere as wide as the set (least_sphere_cost) costs `best` or more, the exact one does too, and the minimum
    // is the same without it. Most sets of a robot's links are long, where the sphere loses by a factor; this
    // skipped CGAL on most calls (docs/fitting.md, "Estimates without most exact spheres").
    if (policy.is_allowed(BvType::sphere)) {
        const double magnitude = std::max(world_box.min.cwiseAbs().maxCoeff(), world_box.max.cwiseAbs().maxCoeff());
        if (least_sphere_cost(widest, magnitude, policy) < best) consider(BvType::sphere, measure(fit_sphere(spheres)));
    }
    return best;
}

double estimate_around(std::span<const BoundingVolume> volumes, const VolumePolicy& policy) {
    std::vector<Sphere> spheres;
    for (const BoundingVolume& bv : volumes) append_generating_spheres(bv, spheres);
    return estimate_weighted_volume(spheres, volumes, policy);
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
