// SPDX-License-Identifier: MIT
// Small helpers more than one test file needs: random vectors and sphere sets from the seeded generator, and a
// bottom-up level over primitives as they are (one node per primitive).
#pragma once

#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "builders/bottom_up.hpp"
#include "hbvh/builders/context.hpp"
#include "hbvh/scene/generate.hpp"

namespace hbvh::test_support {

/// A vector with each coordinate uniform in [-half_width, half_width].
inline Vec3 random_vector(SplitMix64& rng, double half_width) {
    return {rng.uniform(-half_width, half_width), rng.uniform(-half_width, half_width),
            rng.uniform(-half_width, half_width)};
}

/// Where the fitters' loop tests put a random set: a size from 1e-3 to 1e3 and, in each coordinate, an offset from
/// the origin of up to `reach` times that size, so that rounding far from the origin is exercised too.
struct Placement {
    double scale;
    Vec3 offset;
};
inline Placement random_placement(SplitMix64& rng, double reach) {
    const double scale = std::pow(10.0, rng.uniform(-3.0, 3.0));
    return {scale, random_vector(rng, rng.uniform(0.0, reach) * scale)};
}

/// `count` spheres with centres in the cube of half-width `scale` around `offset`, about a third of them points
/// (radius 0) and the rest of radius up to 0.3 scale: the sets the fitters' loop tests draw.
inline std::vector<Sphere> random_spheres(SplitMix64& rng, std::uint64_t count, const Vec3& offset, double scale) {
    std::vector<Sphere> spheres;
    for (std::uint64_t i = 0; i < count; ++i)
        spheres.push_back({offset + random_vector(rng, scale), rng.below(3) == 0 ? 0.0 : rng.uniform(0.0, 0.3) * scale});
    return spheres;
}

/// `primitives` in a seeded random order (Fisher-Yates).
inline std::vector<Primitive> shuffled(std::vector<Primitive> primitives, std::uint64_t seed) {
    SplitMix64 rng(seed);
    for (std::size_t i = primitives.size(); i > 1; --i) std::swap(primitives[i - 1], primitives[rng.below(i)]);
    return primitives;
}

/// The first level of a bottom-up build: one node per primitive, in input order.
inline Level make_level(const std::vector<Primitive>& primitives, const VolumePolicy& policy) {
    std::vector<LevelNode> nodes;
    for (std::uint32_t p = 0; p < primitives.size(); ++p)
        nodes.push_back({primitives[p].volume, policy.weighted_volume(primitives[p].volume), {p}});
    return Level(primitives, std::move(nodes), policy);
}

/// A build context with `policy` and, optionally, a report to fill.
inline BuildContext context_for(const VolumePolicy& policy, BuildReport* report = nullptr) {
    BuildContext context;
    context.policy = policy;
    context.report = report;
    return context;
}

}  // namespace hbvh::test_support
