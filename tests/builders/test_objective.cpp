// SPDX-License-Identifier: MIT
// The calibrated objective (NodeMeasure::minkowski) reaches the builders: the optimal builder's tree under
// each objective is the cheapest under that objective, and on some inputs the two optima differ.
#include <gtest/gtest.h>

#include "hbvh/builders/build.hpp"
#include "hbvh/scene/generate.hpp"
#include "hbvh/tree/stats.hpp"

namespace hbvh {
namespace {

VolumePolicy measured_by(NodeMeasure measure) {
    VolumePolicy policy;
    policy.measure = measure;
    return policy;
}

TEST(Objective, EachOptimumIsCheapestUnderItsOwnObjectiveAndTheyDiffer) {
    const VolumePolicy eq2 = measured_by(NodeMeasure::volume);
    const VolumePolicy calibrated = measured_by(NodeMeasure::minkowski);
    int differing = 0;
    for (std::uint64_t seed = 1; seed <= 4; ++seed) {
        const std::vector<Primitive> primitives = generate_scene({.count = 10, .seed = seed});
        BuildContext context;
        context.policy = eq2;
        const Result<Bvh> by_volume = build(primitives, Algorithm::optimal, context);
        context.policy = calibrated;
        const Result<Bvh> by_minkowski = build(primitives, Algorithm::optimal, context);
        ASSERT_TRUE(by_volume && by_minkowski);
        // Both trees lie in optimal's search space, so each optimum is no dearer under its own objective
        // (the relative slack covers the fits' rounding).
        EXPECT_LE(cost(*by_volume, eq2), cost(*by_minkowski, eq2) * (1 + 1e-12)) << "seed " << seed;
        EXPECT_LE(cost(*by_minkowski, calibrated), cost(*by_volume, calibrated) * (1 + 1e-12)) << "seed " << seed;
        if (cost(*by_minkowski, calibrated) < cost(*by_volume, calibrated) * (1 - 1e-9)) ++differing;
    }
    // A builder that ignored the measure would build the same tree under both.
    EXPECT_GT(differing, 0);
}

}  // namespace
}  // namespace hbvh
