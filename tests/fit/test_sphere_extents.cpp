// SPDX-License-Identifier: MIT
// sphere_extents, the loop under every box fit (four lanes at once where the processor has AVX2): against a
// plain loop over the spheres that forms each coordinate in the documented order, bit for bit, and against
// the exact extents in long double within rounding; folding the spheres in blocks gives the same extents.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "../../src/fit/sphere_extents.hpp"
#include "hbvh/geometry/capsule.hpp"
#include "support/test_helpers.hpp"

namespace hbvh {
namespace {

using test_support::random_placement;
using test_support::random_spheres;
using test_support::random_vector;

TEST(SphereExtents, MatchesAPlainLoopBitForBitAndTheExactExtentsWithinRounding) {
    SplitMix64 rng(41);
    for (int trial = 0; trial < 3000; ++trial) {
        const auto [scale, offset] = random_placement(rng, 1e3);
        const auto count = rng.below(50);  // none too: empty extents
        const std::vector<Sphere> spheres = random_spheres(rng, count, offset, scale);
        // A rotation, or any matrix (the fitters pass rotations; the loop must not assume one).
        const Mat3 frame = trial % 4 == 3 ? Mat3(Mat3::Random()) : rng.rotation();
        const detail::SphereExtents extents = detail::sphere_extents(spheres, frame);

        Vec3 low = Vec3::Constant(std::numeric_limits<double>::infinity());
        Vec3 high = -low;
        for (const Sphere& s : spheres)
            for (int axis = 0; axis < 3; ++axis) {
                const double along = (s.center.x() * frame(0, axis) + s.center.y() * frame(1, axis)) +
                                     s.center.z() * frame(2, axis);
                low[axis] = std::min(low[axis], along - s.radius);
                high[axis] = std::max(high[axis], along + s.radius);
            }
        ASSERT_EQ(extents.low, low) << trial;
        ASSERT_EQ(extents.high, high) << trial;

        // Independent of the order: each extent in long double, then compared within rounding of the coordinates.
        for (int axis = 0; axis < 3; ++axis) {
            long double exact_low = std::numeric_limits<long double>::infinity(), exact_high = -exact_low;
            double magnitude = 0.0;
            for (const Sphere& s : spheres) {
                long double along = 0.0L;
                for (int k = 0; k < 3; ++k) along += static_cast<long double>(s.center[k]) * frame(k, axis);
                exact_low = std::min(exact_low, along - s.radius);
                exact_high = std::max(exact_high, along + s.radius);
                magnitude = std::max(magnitude, s.center.cwiseAbs().sum() * frame.col(axis).cwiseAbs().maxCoeff() + s.radius);
            }
            if (spheres.empty()) continue;
            EXPECT_NEAR(static_cast<double>(exact_low), extents.low[axis], 1e-15 * magnitude) << trial;
            EXPECT_NEAR(static_cast<double>(exact_high), extents.high[axis], 1e-15 * magnitude) << trial;
        }

        // Folded in blocks of any size: the same extents (min and max do not depend on the grouping).
        detail::SphereExtents folded;
        const std::size_t block = 1 + rng.below(9);
        for (std::size_t i = 0; i < spheres.size(); i += block)
            detail::extend_extents(std::span<const Sphere>(spheres).subspan(i, std::min(block, spheres.size() - i)),
                                   frame, folded);
        EXPECT_EQ(folded.low, extents.low) << trial;
        EXPECT_EQ(folded.high, extents.high) << trial;
    }
}

TEST(SphereExtents, HalfExtentsFromACentreMatchAPlainLoopAndTheExactReach) {
    SplitMix64 rng(43);
    for (int trial = 0; trial < 3000; ++trial) {
        const auto [scale, offset] = random_placement(rng, 1e3);
        const auto count = 1 + rng.below(50);
        const std::vector<Sphere> spheres = random_spheres(rng, count, offset, scale);
        const Mat3 frame = rng.rotation();
        const Vec3 center = offset + random_vector(rng, 0.1 * scale);
        const Vec3 start = Vec3(rng.uniform(0.0, 1.0), rng.uniform(0.0, 1.0), rng.uniform(0.0, 1.0)) * scale;
        Vec3 half = start;
        detail::extend_half_extents(spheres, frame, center, half);

        Vec3 expected = start;
        for (const Sphere& s : spheres) {
            const Vec3 d = s.center - center;
            for (int axis = 0; axis < 3; ++axis) {
                const double along = (d.x() * frame(0, axis) + d.y() * frame(1, axis)) + d.z() * frame(2, axis);
                expected[axis] = std::max(expected[axis], std::abs(along) + s.radius);
            }
        }
        ASSERT_EQ(half, expected) << trial;

        // Against the reach in long double, and the box it makes holds every sphere as Obb::contains measures it
        // once padded by the fitters' rounding pad (four units in the last place of the largest half extent).
        for (int axis = 0; axis < 3; ++axis) {
            long double reach = start[axis];
            for (const Sphere& s : spheres) {
                long double along = 0.0L;
                for (int k = 0; k < 3; ++k)
                    along += (static_cast<long double>(s.center[k]) - center[k]) * frame(k, axis);
                reach = std::max(reach, std::abs(along) + s.radius);
            }
            EXPECT_NEAR(static_cast<double>(reach), half[axis], 1e-15 * (half.maxCoeff() + scale)) << trial;
        }
        const Obb box{center, frame, half.array() + half.maxCoeff() * 0x1.0p-50};
        for (const Sphere& s : spheres) EXPECT_TRUE(box.contains(s)) << trial;
    }
}

TEST(SphereExtents, LineReachMatchesAPlainLoopAndTheExactDistances) {
    // Four spheres at a time and a scalar tail: every count from 0 to 13 meets both, and the blocks must agree
    // with the documented scalar order bit for bit.
    SplitMix64 rng(47);
    for (int trial = 0; trial < 3000; ++trial) {
        const auto [scale, offset] = random_placement(rng, 1e3);
        const auto count = trial < 140 ? static_cast<std::uint64_t>(trial % 14) : rng.below(60);
        const std::vector<Sphere> spheres = random_spheres(rng, count, offset, scale);
        const Vec3 origin = offset + random_vector(rng, 0.2 * scale);
        const Vec3 axis = rng.rotation().col(0);
        const detail::LineReach reach = detail::line_reach(spheres, origin, axis);

        detail::LineReach expected;
        for (const Sphere& s : spheres) {
            const double dx = s.center.x() - origin.x(), dy = s.center.y() - origin.y(), dz = s.center.z() - origin.z();
            const double t = (dx * axis.x() + dy * axis.y()) + dz * axis.z();
            const double ex = dx - t * axis.x(), ey = dy - t * axis.y(), ez = dz - t * axis.z();
            expected.radius = std::max(expected.radius, std::sqrt((ex * ex + ey * ey) + ez * ez) + s.radius);
            expected.t_min = std::min(expected.t_min, t);
            expected.t_max = std::max(expected.t_max, t);
        }
        ASSERT_EQ(reach.radius, expected.radius) << trial;
        ASSERT_EQ(reach.t_min, expected.t_min) << trial;
        ASSERT_EQ(reach.t_max, expected.t_max) << trial;
        if (spheres.empty()) continue;

        // Independent of the order: the distances in long double, and the capsule it makes (padded as the fitters
        // pad it) holds every sphere by Capsule::contains.
        long double radius = 0.0L;
        for (const Sphere& s : spheres) {
            long double d[3], t = 0.0L, squared = 0.0L;
            for (int k = 0; k < 3; ++k) d[k] = static_cast<long double>(s.center[k]) - origin[k];
            for (int k = 0; k < 3; ++k) t += d[k] * axis[k];
            for (int k = 0; k < 3; ++k) squared += (d[k] - t * axis[k]) * (d[k] - t * axis[k]);
            radius = std::max(radius, std::sqrt(squared) + s.radius);
        }
        EXPECT_NEAR(static_cast<double>(radius), reach.radius, 1e-13 * (reach.radius + scale)) << trial;
        const Capsule capsule{origin + reach.t_min * axis, origin + reach.t_max * axis,
                              reach.radius + reach.radius * 0x1.0p-48};
        // Within rounding of the coordinates, which sit up to 1e3 times the set's size from the origin here (the
        // loop this replaced, Eigen's dot and norm, left the same spheres outside by as much).
        for (const Sphere& s : spheres)
            EXPECT_TRUE(capsule.contains(s, 1e-12 * (capsule.radius + offset.cwiseAbs().sum()))) << trial;
    }
}

}  // namespace
}  // namespace hbvh
