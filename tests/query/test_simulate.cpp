// SPDX-License-Identifier: MIT
// The simulator on multi-level trees from several builders: deterministic counters for a seed, only
// root-overlapping queries measured, the same trajectory for tandem traversal and the two-level baseline,
// and counters checked against values known without running a query.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "hbvh/builders/build.hpp"
#include "hbvh/geometry/overlap.hpp"
#include "hbvh/tree/stats.hpp"
#include "hbvh/query/simulate.hpp"
#include "hbvh/scene/generate.hpp"

namespace hbvh {
namespace {

/// Builders whose trees have inner levels below the root (two-level's would not exercise the descent).
constexpr Algorithm multi_level_builders[] = {Algorithm::split, Algorithm::insertion, Algorithm::merge,
                                              Algorithm::bnb_exact, Algorithm::scale};

Bvh make_object(std::uint32_t count, Algorithm algorithm) {
    const auto primitives = generate_scene({.count = count, .seed = 11});
    Bvh bvh = build(primitives, algorithm).value();
    EXPECT_GE(compute_stats(bvh).height, 2u) << to_string(algorithm);
    return bvh;
}

/// Primitive pairs of two copies of `object` at the same pose that overlap, by brute force in the world
/// frame: the pairs every "totally colliding" query must find.
std::uint64_t self_overlapping_pairs(const Bvh& object, const RigidTransform& pose) {
    std::uint64_t count = 0;
    for (const Primitive& a : object.primitives)
        for (const Primitive& b : object.primitives)
            count += overlaps(transformed(a.volume, pose), transformed(b.volume, pose)) ? 1 : 0;
    return count;
}

void expect_same_counters(const QueryStats& x, const QueryStats& y, const std::string& what) {
    EXPECT_EQ(x.queries, y.queries) << what;
    EXPECT_EQ(x.intersecting, y.intersecting) << what;
    EXPECT_EQ(x.mean_bv_tests, y.mean_bv_tests) << what;
    EXPECT_EQ(x.mean_primitive_tests, y.mean_primitive_tests) << what;
    EXPECT_EQ(x.mean_nodes_visited, y.mean_nodes_visited) << what;
}

TEST(Simulate, DeterministicAndMeasuresOnlyRootOverlaps) {
    for (const Algorithm algorithm : multi_level_builders) {
        const Bvh object = make_object(13, algorithm);
        for (const QueryMethod method : {QueryMethod::tandem, QueryMethod::two_level}) {
            const std::string what = std::string(to_string(algorithm)) +
                                     (method == QueryMethod::tandem ? " / tandem" : " / two-level");
            SimulateOptions options{.collision_count = 200, .seed = 3, .method = method};
            const SimulationResult r = simulate(object, options);
            ASSERT_TRUE(r.complete) << what;
            EXPECT_EQ(r.moving.queries, 200u) << what;
            EXPECT_GE(r.moving.mean_nodes_visited, 1.0) << what;  // every measured query got past the roots
            EXPECT_GT(r.moving.intersecting, 0u) << what;         // and some of them were real contacts
            EXPECT_LT(r.moving.intersecting, r.moving.queries) << what;
            EXPECT_EQ(r.total.queries, 200u) << what;
            EXPECT_EQ(r.total.intersecting, 200u) << what;  // a copy on itself always collides

            const SimulationResult again = simulate(object, options);
            expect_same_counters(r.moving, again.moving, what);
            expect_same_counters(r.total, again.total, what);
            EXPECT_EQ(r.steps, again.steps) << what;
            EXPECT_EQ(r.restarts, again.restarts) << what;

            options.seed = 4;
            EXPECT_NE(simulate(object, options).steps, r.steps) << what;
        }
    }
}

TEST(Simulate, TandemAndTwoLevelSeeTheSameCollisions) {
    // With every pair reported, the first reported pair (the contact normal) is the smallest, whichever
    // method found it, so both methods must take the same trajectory and count the same contacts.
    for (const Algorithm algorithm : multi_level_builders) {
        if (algorithm == Algorithm::bnb_exact) continue;  // 27 primitives: seconds under the sanitizers
        const std::string what(to_string(algorithm));
        const Bvh object = make_object(27, algorithm);
        SimulateOptions options{.collision_count = 150, .seed = 9, .mode = CollideMode::all};
        const SimulationResult tandem = simulate(object, options);
        options.method = QueryMethod::two_level;
        const SimulationResult baseline = simulate(object, options);
        EXPECT_EQ(tandem.steps, baseline.steps) << what;
        EXPECT_EQ(tandem.restarts, baseline.restarts) << what;
        EXPECT_EQ(tandem.moving.queries, baseline.moving.queries) << what;
        EXPECT_EQ(tandem.moving.intersecting, baseline.moving.intersecting) << what;
        EXPECT_EQ(tandem.total.intersecting, baseline.total.intersecting) << what;
    }
}

TEST(Simulate, TotallyCollidingCountersMatchBruteForce) {
    // Two copies at one pose: the baseline tests every one of the n^2 primitive pairs; the hierarchy must
    // test at least every overlapping pair (it reports them all in `all` mode) and never more than n^2 (its
    // flat pairs test small subtrees leaf by leaf, which in this regime may reach every pair). The number of overlapping pairs is counted here at a few poses: it does not depend
    // on the pose beyond rounding, so it is the same for every query.
    for (const Algorithm algorithm : multi_level_builders) {
        const std::string what(to_string(algorithm));
        const Bvh object = make_object(13, algorithm);
        const double n = static_cast<double>(object.primitives.size());
        const std::uint64_t overlapping = self_overlapping_pairs(object, RigidTransform::identity());
        EXPECT_EQ(self_overlapping_pairs(object, random_transform(5, 3.0)), overlapping) << what;
        SimulateOptions options{.collision_count = 50, .seed = 2, .mode = CollideMode::all};
        options.method = QueryMethod::two_level;
        const SimulationResult baseline = simulate(object, options);
        EXPECT_EQ(baseline.total.mean_primitive_tests, n * n) << what;
        options.method = QueryMethod::tandem;
        const SimulationResult tandem = simulate(object, options);
        EXPECT_GE(tandem.total.mean_primitive_tests, static_cast<double>(overlapping)) << what;
        EXPECT_LE(tandem.total.mean_primitive_tests, n * n) << what;
    }
}

}  // namespace
}  // namespace hbvh
