// SPDX-License-Identifier: MIT
// estimate_weighted_volume, the heuristic builders' price of a group: it computes the exact enclosing sphere only
// where a floor says the sphere can still be the cheapest candidate. Checked against the estimate without the
// sphere kind and the exact sphere computed every time, on long, flat and round sets, under both measures and
// under weights that make the sphere cheap or dear.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "builders/heuristic_support.hpp"
#include "hbvh/fit/fit.hpp"
#include "support/test_helpers.hpp"

namespace hbvh {
namespace {

/// Random spheres stretched by a random factor per axis (down to 1 %), then turned and moved: long rods, flat
/// plates and round clouds.
std::vector<Sphere> stretched_spheres(SplitMix64& rng) {
    const Vec3 stretch(1.0, rng.uniform(0.01, 1.0), rng.uniform(0.01, 1.0));
    const Mat3 rotation = rng.rotation();
    const Vec3 offset = test_support::random_vector(rng, 50.0);
    std::vector<Sphere> spheres = test_support::random_spheres(rng, 1 + rng.below(40), Vec3::Zero(), 1.0);
    for (Sphere& s : spheres) {
        s.center = rotation * s.center.cwiseProduct(stretch) + offset;
        s.radius *= stretch.minCoeff();
    }
    return spheres;
}

TEST(Estimates, SphereFloorNeverChangesTheEstimate) {
    SplitMix64 rng(2026'12'07);
    std::size_t sphere_cheapest = 0, sphere_dearer = 0;
    for (int trial = 0; trial < 600; ++trial) {
        SCOPED_TRACE(trial);
        const std::vector<Sphere> spheres = stretched_spheres(rng);
        VolumePolicy policy;
        policy.measure = trial % 3 == 0 ? NodeMeasure::minkowski : NodeMeasure::volume;
        for (double& w : policy.weight) w = rng.uniform(0.5, 2.0);
        policy.weight[static_cast<std::size_t>(BvType::sphere)] = rng.uniform(0.2, 2.0);
        const std::vector<BoundingVolume> hints{Obb{Vec3::Zero(), rng.rotation(), Vec3::Ones()}};
        VolumePolicy without_sphere = policy;
        without_sphere.allowed[static_cast<std::size_t>(BvType::sphere)] = false;
        const double others = detail::estimate_weighted_volume(spheres, hints, without_sphere);
        const double sphere = policy.weighted_volume(fit_sphere(spheres));
        const double estimate = detail::estimate_weighted_volume(spheres, hints, policy);
        EXPECT_EQ(estimate, std::min(others, sphere));
        ++(sphere < others ? sphere_cheapest : sphere_dearer);
    }
    // Both sides of the floor were exercised.
    EXPECT_GT(sphere_cheapest, 50u);
    EXPECT_GT(sphere_dearer, 50u);
}

}  // namespace
}  // namespace hbvh
