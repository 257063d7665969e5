// SPDX-License-Identifier: MIT
// B&B-Enlarge's candidate heuristic: grow a node's BV in 5 % steps until it collides (survey §3, Fig. 11).
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <tuple>

#include "hbvh/assert.hpp"
#include "candidates.hpp"
#include "hbvh/geometry/overlap.hpp"

namespace hbvh {
namespace {

/// The last step worth trying for a BV: the first k whose scaled world AABB holds the level's bounds
/// ("the enlarged BV spans the whole level"), capped by `max_steps` for BVs flat along some axis.
std::uint32_t last_step(const BoundingVolume& bv, const Aabb& level_bounds, const EnlargeOptions& options) {
    // Scaling about the centre scales the world AABB about the same centre, so this is per axis.
    const Aabb box = world_aabb(bv);
    const Vec3 c = box.center();
    const Vec3 r = box.half_extents();
    double needed = 1.0;
    for (int a = 0; a < 3; ++a) {
        const double reach = std::max(c[a] - level_bounds.min[a], level_bounds.max[a] - c[a]);
        if (reach <= 0.0) continue;
        if (r[a] <= 0.0) return options.max_steps;
        needed = std::max(needed, reach / r[a]);
    }
    const double steps = std::ceil((needed - 1.0) / options.step);
    return steps >= static_cast<double>(options.max_steps) ? options.max_steps : static_cast<std::uint32_t>(steps);
}

/// The first step k in [0, last] at which B scaled by 1 + k step overlaps `other`, if any. B is convex and
/// contains its centre, so the scaled copies are nested and overlap is monotone in k: a binary search finds
/// exactly the step that stepping one at a time would stop at, with O(log last) overlap tests.
std::optional<std::uint32_t> first_colliding_step(const BoundingVolume& bv, const BoundingVolume& other,
                                                  std::uint32_t last, double step) {
    auto hits = [&](std::uint32_t k) { return overlaps(scaled_about_center(bv, 1.0 + step * k), other); };
    if (!hits(last)) return std::nullopt;
    std::uint32_t lo = 0, hi = last;  // invariant: hits(hi)
    if (hits(lo)) return lo;
    while (hi - lo > 1) {
        const std::uint32_t mid = lo + (hi - lo) / 2;
        (hits(mid) ? hi : lo) = mid;
    }
    return hi;
}

/// The number of subsets of `k` colliders of size 1..max_extra, saturating at `cap` + 1.
std::uint64_t subset_count(std::uint64_t k, std::uint64_t max_extra, std::uint64_t cap) {
    std::uint64_t total = 0;
    std::uint64_t binomial = 1;  // C(k, s), built up s by s
    for (std::uint64_t s = 1; s <= max_extra && s <= k; ++s) {
        // C(k, s) = C(k, s - 1) (k - s + 1) / s, in long double to pass the cap without overflow.
        const long double next = static_cast<long double>(binomial) * static_cast<long double>(k - s + 1) / s;
        if (next > static_cast<long double>(cap)) return cap + 1;
        binomial = static_cast<std::uint64_t>(next + 0.5L);
        total += binomial;
        if (total > cap) return cap + 1;
    }
    return total;
}

/// Appends every subset of `colliders` of size 1..max_extra, each joined with `node`; the level's deadline is
/// checked every few thousand subsets (one node's could take seconds).
void append_subsets(const Level& level, std::uint32_t node, const std::vector<std::uint32_t>& colliders,
                    std::uint32_t max_extra, std::vector<std::vector<std::uint32_t>>& out) {
    std::vector<std::uint32_t> chosen;
    std::uint32_t since_check = 0;
    // Depth-first over colliders in canonical order; each prefix choice is emitted once.
    auto recurse = [&](auto&& self, std::size_t from) -> void {
        for (std::size_t i = from; i < colliders.size(); ++i) {
            if (++since_check == 4096) {
                since_check = 0;
                level.check_deadline();
            }
            chosen.push_back(colliders[i]);
            std::vector<std::uint32_t> set = chosen;
            set.push_back(node);
            out.push_back(std::move(set));
            if (chosen.size() < max_extra) self(self, i + 1);
            chosen.pop_back();
        }
    };
    recurse(recurse, 0);
}

}  // namespace

std::uint32_t enlarge_max_group_size(std::uint32_t node_count) {
    // floor(lg n) by bit length: exact, no floating point.
    std::uint32_t lg = 0;
    while ((node_count >> (lg + 1)) != 0) ++lg;
    return std::max<std::uint32_t>(2, lg);
}

BoundingVolume scaled_about_center(const BoundingVolume& bv, double scale) {
    return std::visit(Overloaded{
                          [&](const Aabb& box) -> BoundingVolume {
                              const Vec3 c = box.center(), h = scale * box.half_extents();
                              return Aabb{c - h, c + h};
                          },
                          [&](const Obb& box) -> BoundingVolume {
                              return Obb{box.center, box.rotation, scale * box.half_extents};
                          },
                          [&](const Sphere& s) -> BoundingVolume { return Sphere{s.center, scale * s.radius}; },
                          [&](const Capsule& cap) -> BoundingVolume {
                              const Vec3 c = cap.center();
                              return Capsule{c + scale * (cap.p0 - c), c + scale * (cap.p1 - c), scale * cap.radius};
                          },
                      },
                      bv);
}

std::vector<std::vector<std::uint32_t>> enlarge_candidates(const Level& level, const EnlargeOptions& options) {
    HBVH_ASSERT(options.step > 0.0);
    const std::uint32_t n = level.size();
    const std::uint32_t max_size = enlarge_max_group_size(n);
    const std::uint32_t wanted = std::min(std::max<std::uint32_t>(options.min_collisions, 1), n - 1);
    std::vector<std::vector<std::uint32_t>> sets;
    for (std::uint32_t i = 0; i < n; ++i) {
        level.check_deadline();  // each node tests every other: the only place this heuristic can stop in time
        const BoundingVolume& bv = level.nodes()[i].volume;
        const std::uint32_t last = last_step(bv, level.bounds(), options);
        // (first colliding step, squared centre distance, node) for every node B ever reaches.
        std::vector<std::tuple<std::uint32_t, double, std::uint32_t>> reached;
        const Vec3 centre = world_aabb(bv).center();
        for (std::uint32_t j = 0; j < n; ++j) {
            if (j == i) continue;
            const BoundingVolume& other = level.nodes()[j].volume;
            if (const auto k = first_colliding_step(bv, other, last, options.step))
                reached.emplace_back(*k, (world_aabb(other).center() - centre).squaredNorm(), j);
        }
        if (reached.empty()) continue;
        std::sort(reached.begin(), reached.end());
        // Stop at the step where the `wanted`-th collision happens; everything colliding by then counts.
        const std::uint32_t stop = std::get<0>(reached[std::min<std::size_t>(wanted, reached.size()) - 1]);
        std::vector<std::uint32_t> colliders;
        for (const auto& [k, distance, j] : reached) {
            if (k > stop) break;
            if (options.max_colliders > 0 && colliders.size() == options.max_colliders) break;
            colliders.push_back(j);
        }
        // The first colliders (in the order reached) whose subsets stay within the cap.
        if (options.max_subsets_per_node > 0)
            while (colliders.size() > 1 &&
                   subset_count(colliders.size(), max_size - 1, options.max_subsets_per_node) > options.max_subsets_per_node)
                colliders.pop_back();
        std::sort(colliders.begin(), colliders.end());
        append_subsets(level, i, colliders, max_size - 1, sets);
    }
    return sets;
}

}  // namespace hbvh
