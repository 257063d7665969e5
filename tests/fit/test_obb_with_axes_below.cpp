// SPDX-License-Identifier: MIT
// obb_with_axes_below, the early-out box binned uses on DiTO's frames: when it returns a box it must be
// obb_with_axes' box bit for bit, and when it returns none obb_with_axes' box must not be below the limit
// (else binned would drop a box that should have won). Checked against obb_with_axes itself, with limits
// placed just above, at and just below each true volume.
#include <gtest/gtest.h>

#include <vector>

#include "../../src/fit/frames.hpp"
#include "support/test_helpers.hpp"

namespace hbvh {
namespace {

using test_support::random_placement;
using test_support::random_spheres;

TEST(ObbWithAxesBelow, ReturnsTheSameBoxOrOneNotBelowTheLimit) {
    SplitMix64 rng(17);
    int returned = 0;
    int dropped = 0;
    for (int trial = 0; trial < 2000; ++trial) {
        const auto [scale, offset] = random_placement(rng, 1e4);
        const auto count = 1 + rng.below(40);
        const std::vector<Sphere> spheres = random_spheres(rng, count, offset, scale);
        const Mat3 rotation = rng.rotation();
        const Obb exact = detail::obb_with_axes(spheres, rotation);
        const double v = exact.volume();
        for (const double factor : {2.0, 1.0 + 1e-9, 1.0, 1.0 - 1e-9, 0.5, 0.01}) {
            const double limit = v * factor;
            const std::optional<Obb> box = detail::obb_with_axes_below(spheres, rotation, limit);
            if (box) {
                ++returned;
                EXPECT_EQ(box->center, exact.center) << trial;
                EXPECT_EQ(box->rotation, exact.rotation) << trial;
                EXPECT_EQ(box->half_extents, exact.half_extents) << trial;
            } else {
                ++dropped;
                EXPECT_GE(v, limit * (1.0 - 1e-12)) << "dropped a box below the limit, trial " << trial;
            }
        }
        // A limit above the volume by more than rounding always gets the box (a lone point has volume 0,
        // and nothing is below a limit of 0).
        if (v > 0.0) {
            EXPECT_TRUE(detail::obb_with_axes_below(spheres, rotation, v * 2.0).has_value()) << trial;
        }
    }
    // Both outcomes were exercised.
    EXPECT_GT(returned, 1000);
    EXPECT_GT(dropped, 1000);
}

}  // namespace
}  // namespace hbvh
