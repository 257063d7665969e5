// SPDX-License-Identifier: MIT
// Query time per pose: tandem traversal (every registered builder) vs the two-level baseline, on
// generated scenes whose roots overlap, with the work counters and a checksum of the answers.
#include <benchmark/benchmark.h>

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "hbvh/build/build.hpp"
#include "hbvh/geometry/overlap.hpp"
#include "hbvh/query/tandem_traversal.hpp"
#include "hbvh/scene/generate.hpp"

namespace hbvh {
namespace {

/// Two copies of one generated object and 256 seeded poses of the second copy whose root BVs overlap
/// the first's (the survey's measuring condition), the first copy at the identity.
struct QueryScenario {
    Bvh bvh;
    QueryTree tree;
    std::vector<RigidTransform> poses;
};

QueryScenario make_scenario(std::uint32_t count, Algorithm algorithm) {
    const auto primitives = generate_scene({.count = count, .seed = 2024});
    Bvh bvh = build(primitives, algorithm).value();
    QueryTree tree(bvh);
    Aabb bounds = Aabb::empty();
    for (const Primitive& p : primitives) bounds = bounds.merged(world_aabb(p.volume));
    const Vec3 center = bounds.center();
    const double radius = 0.5 * (bounds.max - bounds.min).norm();
    std::vector<RigidTransform> poses;
    SplitMix64 rng(99);
    while (poses.size() < 256) {
        const Mat3 rotation = rng.rotation();
        const Vec3 offset = radius * Vec3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
        const RigidTransform pose{rotation, center + offset - rotation * center};
        if (overlaps(bvh.root().volume, transformed(bvh.root().volume, pose))) poses.push_back(pose);
    }
    return {std::move(bvh), std::move(tree), std::move(poses)};
}

/// Scenarios are built on first use (so that filtered runs skip the building) and kept for later runs.
const QueryScenario& scenario_for(std::uint32_t count, Algorithm algorithm) {
    static std::map<std::pair<std::uint32_t, Algorithm>, std::unique_ptr<QueryScenario>> cache;
    auto& slot = cache[{count, algorithm}];
    if (!slot) slot = std::make_unique<QueryScenario>(make_scenario(count, algorithm));
    return *slot;
}

template <bool two_level>
void run_queries(benchmark::State& state, const QueryScenario& scenario, CollideMode mode) {
    CollideResult result;
    const RigidTransform identity = RigidTransform::identity();
    // Checksum of the answers over one full cycle of poses: equal across methods when they agree.
    std::uint64_t checksum = 0;
    for (const RigidTransform& pose : scenario.poses) {
        if constexpr (two_level)
            collide_two_level(scenario.tree, identity, scenario.tree, pose, mode, result);
        else
            collide(scenario.tree, identity, scenario.tree, pose, mode, result);
        for (const auto& [i, j] : result.pairs) checksum += 31u * i + j + 1u;
    }
    std::size_t k = 0;
    std::uint64_t queries = 0, bv_tests = 0, primitive_tests = 0, nodes = 0;
    for (auto _ : state) {
        const RigidTransform& pose = scenario.poses[k];
        k = (k + 1) % scenario.poses.size();
        if constexpr (two_level)
            collide_two_level(scenario.tree, identity, scenario.tree, pose, mode, result);
        else
            collide(scenario.tree, identity, scenario.tree, pose, mode, result);
        benchmark::DoNotOptimize(result.pairs.data());
        ++queries;
        bv_tests += result.bv_tests;
        primitive_tests += result.primitive_tests;
        nodes += result.nodes_visited;
    }
    const double n = static_cast<double>(std::max<std::uint64_t>(queries, 1));
    state.counters["bv_tests"] = static_cast<double>(bv_tests) / n;
    state.counters["primitive_tests"] = static_cast<double>(primitive_tests) / n;
    state.counters["nodes_visited"] = static_cast<double>(nodes) / n;
    state.counters["checksum"] = static_cast<double>(checksum);
}

void register_all() {
    for (const std::uint32_t count : {13u, 27u}) {
        for (const CollideMode mode : {CollideMode::all, CollideMode::first}) {
            const std::string suffix = "/" + std::to_string(count) + (mode == CollideMode::all ? "/all" : "/first");
            for (const AlgorithmInfo& info : algorithms()) {
                const Algorithm algorithm = info.algorithm;
                benchmark::RegisterBenchmark(("tandem/" + std::string(info.name) + suffix).c_str(),
                                             [count, algorithm, mode](benchmark::State& state) {
                                                 run_queries<false>(state, scenario_for(count, algorithm), mode);
                                             });
            }
            const Algorithm baseline_tree = algorithms().front().algorithm;
            benchmark::RegisterBenchmark(("two_level_query" + suffix).c_str(),
                                         [count, baseline_tree, mode](benchmark::State& state) {
                                             run_queries<true>(state, scenario_for(count, baseline_tree), mode);
                                         });
        }
    }
}

/// Registers at static-initialisation time, before BENCHMARK_MAIN parses the command line.
const bool query_benchmarks_registered = (register_all(), true);

}  // namespace
}  // namespace hbvh
