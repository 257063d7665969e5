// SPDX-License-Identifier: MIT
// The capsule lower bound fit_best uses to skip the capsule fitter: it must never exceed a capsule that
// contains the spheres, or fit_best would skip a capsule that should have won.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "../../src/fit/capsule_bound.hpp"
#include "hbvh/fit/fit.hpp"
#include "hbvh/scene/generate.hpp"
#include "support/test_helpers.hpp"

namespace hbvh {
namespace {

using test_support::random_vector;

/// Spheres inside a random capsule, plus its two end spheres: the fitter then finds that capsule (or a
/// smaller one), so the bound is checked where it is closest to the truth.
std::vector<Sphere> capsule_filling(SplitMix64& rng, Capsule& capsule) {
    const double scale = std::pow(10.0, rng.uniform(-2.0, 2.0));
    const Vec3 center = random_vector(rng, 100.0 * scale);
    const Vec3 axis = rng.rotation().col(0) * rng.uniform(0.0, 3.0) * scale;
    capsule = {center - axis, center + axis, rng.uniform(0.1, 1.0) * scale};
    std::vector<Sphere> spheres{{capsule.p0, capsule.radius}, {capsule.p1, capsule.radius}};
    const auto count = rng.below(30);
    for (std::uint64_t i = 0; i < count; ++i) {
        const double r = rng.uniform(0.0, 0.5) * capsule.radius;
        const Vec3 on_axis = capsule.p0 + rng.uniform(0.0, 1.0) * (capsule.p1 - capsule.p0);
        Vec3 offset = random_vector(rng, 1.0);
        if (offset.norm() > 0.0) offset = offset.normalized() * rng.uniform(0.0, capsule.radius - r);
        spheres.push_back({on_axis + offset, r});
    }
    return spheres;
}

double bound_of(std::span<const Sphere> spheres, std::span<const Mat3> hints) {
    const detail::HullSummary hull = detail::summarize_hull(spheres);
    const detail::SphereProxy proxy = detail::make_proxy(spheres, hull);
    const std::vector<Mat3> planes{fit_obb(spheres, hints).rotation, Mat3::Identity()};
    return detail::capsule_volume_lower_bound(proxy, planes);
}

TEST(CapsuleBound, NeverExceedsAContainingCapsule) {
    SplitMix64 rng(515);
    for (int i = 0; i < 300; ++i) {
        Capsule truth;
        const std::vector<Sphere> spheres = capsule_filling(rng, truth);
        const double bound = bound_of(spheres, {});
        EXPECT_LE(bound, truth.volume() * (1.0 + 1e-9)) << "capsule set " << i;
        EXPECT_LE(bound, fit_capsule(spheres).volume() * (1.0 + 1e-9)) << "capsule set " << i;
    }
    for (std::uint32_t i = 0; i < 120; ++i) {
        SceneOptions options;
        options.count = 1 + i % 16;
        options.seed = 7000 + i;
        FitInput input;
        for (const Primitive& p : generate_scene(options)) input.add(p.volume);
        EXPECT_LE(bound_of(input.spheres, input.hint_axes),
                  fit_capsule(input.spheres, input.hint_axes).volume() * (1.0 + 1e-9))
            << "scene " << i;
    }
}

TEST(CapsuleBound, IsTightForABoxAlongItsLongSide) {
    // A 4 x 1 x 1 box: a capsule along the long side needs radius about sqrt(2)/2, and the diagonal
    // planes see that. The bound must be a useful fraction of the fitted capsule, or fit_best would
    // never skip the fitter.
    const Obb box{Vec3(1, 2, 3), Mat3::Identity(), Vec3(2.0, 0.5, 0.5)};
    std::vector<Sphere> corners;
    for (int i = 0; i < 8; ++i) corners.push_back({box.corner(i), 0.0});
    const double bound = bound_of(corners, {});
    const double capsule = fit_capsule(corners).volume();
    EXPECT_LE(bound, capsule * (1.0 + 1e-9));
    EXPECT_GT(bound, 0.5 * capsule);
}

TEST(CapsuleBound, StopsEarlyOnlyAboveEnough) {
    SplitMix64 rng(99);
    for (int i = 0; i < 50; ++i) {
        Capsule truth;
        const std::vector<Sphere> spheres = capsule_filling(rng, truth);
        const detail::HullSummary hull = detail::summarize_hull(spheres);
        const detail::SphereProxy proxy = detail::make_proxy(spheres, hull);
        const std::vector<Mat3> planes{Mat3::Identity()};
        const double full = detail::capsule_volume_lower_bound(proxy, planes);
        const double enough = 0.5 * full;
        const double early = detail::capsule_volume_lower_bound(proxy, planes, enough);
        EXPECT_GE(early, enough);
        EXPECT_LE(early, full);
    }
}

}  // namespace
}  // namespace hbvh
