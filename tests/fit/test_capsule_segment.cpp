// SPDX-License-Identifier: MIT
// The capsule radius search's filter (src/fit/capsule_segment.hpp): over any radius of the bracket, the kept
// spheres give bit for bit the segment that all of them give (brute force), on random sets along a line.
#include <gtest/gtest.h>

#include <cmath>

#include "../../src/fit/capsule_segment.hpp"
#include "hbvh/scene/generate.hpp"

namespace hbvh {
namespace {

TEST(CapsuleSegment, KeptSpheresGiveTheSameSegmentAcrossTheBracket) {
    SplitMix64 rng(31337);
    std::size_t kept_total = 0, all_total = 0;
    for (int set = 0; set < 300; ++set) {
        detail::AxisDistances all;
        const std::size_t count = 1 + rng.below(120);
        const double spread = std::pow(10.0, rng.uniform(-3.0, 3.0));
        double min_radius = 0.0;  // the smallest radius around every sphere, as the fitter starts from
        for (std::size_t i = 0; i < count; ++i) {
            const double distance = spread * rng.uniform(0.0, 0.5);
            const double own = i % 3 == 0 ? 0.0 : spread * rng.uniform(0.0, 0.3);
            all.axial.push_back(spread * rng.uniform(-2.0, 2.0));
            all.radius.push_back(own);
            all.distance_squared.push_back(distance * distance);
            min_radius = std::max(min_radius, distance + own);
        }
        const auto [t0, t1] = detail::segment_for_radius(all, min_radius);
        const double length = std::max(t1 - t0, spread);
        // Brackets as the search makes them: wide and narrow, near the smallest radius and far above it.
        const double low = min_radius + length * rng.uniform(0.0, 1.0) * rng.uniform(0.0, 1.0);
        const double high = low + length * std::pow(10.0, rng.uniform(-4.0, 0.0));
        detail::AxisDistances kept;
        detail::keep_end_candidates(all, low, high, kept);
        kept_total += kept.axial.size();
        all_total += all.axial.size();
        for (int sample = 0; sample <= 40; ++sample) {
            const double r = sample == 40 ? high : low + (high - low) * rng.uniform(0.0, 1.0);
            const auto expected = detail::segment_for_radius(all, r);
            const auto got = detail::segment_for_radius(kept, r);
            EXPECT_EQ(got.first, expected.first) << "set " << set << " radius " << r;
            EXPECT_EQ(got.second, expected.second) << "set " << set << " radius " << r;
        }
    }
    // The filter is worth its pass only if it drops most spheres.
    EXPECT_LT(kept_total * 2, all_total) << kept_total << " of " << all_total;
}

}  // namespace
}  // namespace hbvh
