// SPDX-License-Identifier: MIT
// The simulator: deterministic counters for a seed, only root-overlapping queries measured.
#include <gtest/gtest.h>

#include "hbvh/build/build.hpp"
#include "hbvh/query/simulate.hpp"
#include "hbvh/scene/generate.hpp"

namespace hbvh {
namespace {

Bvh make_object(std::uint32_t count) {
    const auto primitives = generate_scene({.count = count, .seed = 11});
    return build(primitives, algorithms().front().algorithm).value();
}

void expect_same_counters(const QueryStats& x, const QueryStats& y) {
    EXPECT_EQ(x.queries, y.queries);
    EXPECT_EQ(x.intersecting, y.intersecting);
    EXPECT_EQ(x.mean_bv_tests, y.mean_bv_tests);
    EXPECT_EQ(x.mean_primitive_tests, y.mean_primitive_tests);
    EXPECT_EQ(x.mean_nodes_visited, y.mean_nodes_visited);
}

TEST(Simulate, DeterministicAndMeasuresOnlyRootOverlaps) {
    const Bvh object = make_object(13);
    for (const QueryMethod method : {QueryMethod::tandem, QueryMethod::two_level}) {
        SimulateOptions options{.collision_count = 200, .seed = 3, .method = method};
        const SimulationResult r = simulate(object, options);
        ASSERT_TRUE(r.complete);
        EXPECT_EQ(r.moving.queries, 200u);
        EXPECT_GE(r.moving.mean_nodes_visited, 1.0);  // every measured query got past the roots
        EXPECT_GT(r.moving.intersecting, 0u);         // and some of them were real contacts
        EXPECT_LT(r.moving.intersecting, r.moving.queries);
        EXPECT_EQ(r.total.queries, 200u);
        EXPECT_EQ(r.total.intersecting, 200u);  // a copy on itself always collides
        EXPECT_GE(r.moving.mean_query_ms, 0.0);

        const SimulationResult again = simulate(object, options);
        expect_same_counters(r.moving, again.moving);
        expect_same_counters(r.total, again.total);
        EXPECT_EQ(r.steps, again.steps);
        EXPECT_EQ(r.restarts, again.restarts);

        options.seed = 4;
        EXPECT_NE(simulate(object, options).steps, r.steps);
    }
}

TEST(Simulate, TandemAndTwoLevelSeeTheSameCollisions) {
    // Both methods answer the same question, so the trajectory (and which queries count) is the same.
    const Bvh object = make_object(27);
    SimulateOptions options{.collision_count = 150, .seed = 9, .mode = CollideMode::all};
    const SimulationResult tandem = simulate(object, options);
    options.method = QueryMethod::two_level;
    const SimulationResult baseline = simulate(object, options);
    EXPECT_EQ(tandem.steps, baseline.steps);
    EXPECT_EQ(tandem.moving.intersecting, baseline.moving.intersecting);
    EXPECT_EQ(tandem.total.intersecting, baseline.total.intersecting);
}

}  // namespace
}  // namespace hbvh
