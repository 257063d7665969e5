// SPDX-License-Identifier: MIT
// fit_fast skips the box and sphere candidates that cannot beat the best one so far (under the volume measure).
// Whatever it skips, its answer must enclose every sphere and cost no more than each candidate computed on its
// own: the exact AABB, the box in the world frame and in each hint box's frame, the exact enclosing sphere.
// Sets of every shape (compact, needle-like, flat, a lone sphere), tiny ones far from the origin (where rounding
// is large next to the set's size), and kinds weighted so that each of them wins somewhere.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "../../src/fit/frames.hpp"
#include "hbvh/fit/fit.hpp"
#include "hbvh/fit/fit_fast.hpp"
#include "support/test_helpers.hpp"

namespace hbvh {
namespace {

using test_support::random_vector;

TEST(FitFast, NeverCostlierThanACandidateItMaySkipAndEnclosesEverySphere) {
    SplitMix64 rng(29);
    std::array<int, bv_type_count> wins{};
    for (int trial = 0; trial < 3000; ++trial) {
        const double scale = std::pow(10.0, rng.uniform(-3.0, 3.0));
        // Far from the origin now and then: a set 1e-3 wide at 1e6 rounds at a millionth of its size.
        const Vec3 offset = random_vector(rng, rng.below(4) == 0 ? 1e9 * scale : 10.0 * scale);
        const Vec3 stretch(1.0, rng.below(3) == 0 ? 1e-3 : 1.0, rng.below(3) == 0 ? 1e-2 : 1.0);
        const Mat3 turn = rng.rotation();
        std::vector<Sphere> spheres;
        const auto count = 1 + rng.below(40);
        for (std::uint64_t i = 0; i < count; ++i)
            spheres.push_back({offset + turn * random_vector(rng, scale).cwiseProduct(stretch),
                               rng.below(3) == 0 ? 0.0 : rng.uniform(0.0, 0.3) * scale});
        std::vector<BoundingVolume> hints;
        for (std::uint64_t i = 0, n = rng.below(3); i < n; ++i)
            hints.push_back(Obb{offset, i == 0 ? turn : rng.rotation(), Vec3::Constant(scale)});
        VolumePolicy policy;
        for (double& weight : policy.weight) weight = rng.below(2) == 0 ? 1.0 : rng.uniform(0.3, 3.0);

        const BoundingVolume fitted = fit_fast(spheres, hints, policy);
        const double cost = policy.weighted_volume(fitted);
        ++wins[static_cast<std::size_t>(type_of(fitted))];
        for (const Sphere& s : spheres) ASSERT_LE(protrusion(fitted, s), 1e-9 * (scale + offset.norm())) << trial;
        // Each candidate alone, as fit_fast would make it without skipping: it may only be no cheaper.
        std::vector<BoundingVolume> candidates{fit_aabb(spheres), detail::obb_with_axes(spheres, Mat3::Identity()),
                                               fit_sphere(spheres)};
        for (const BoundingVolume& hint : hints) candidates.push_back(detail::obb_with_axes(spheres, std::get<Obb>(hint).rotation));
        for (const BoundingVolume& candidate : candidates)
            ASSERT_LE(cost, policy.weighted_volume(candidate)) << "trial " << trial << ": a cheaper " << to_string(type_of(candidate));
    }
    // Every kind won somewhere, so every skip was exercised against a winner.
    for (const int won : wins) EXPECT_GT(won, 50);
}

}  // namespace
}  // namespace hbvh
