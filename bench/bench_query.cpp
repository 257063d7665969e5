// SPDX-License-Identifier: MIT
// Query time per pose: tandem traversal (every registered builder) vs the two-level baseline, on
// generated scenes whose roots overlap, with the work counters and a checksum of the answers. Every
// method's answers are first compared with brute force over primitive pairs: a wrong answer fails the run.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "hbvh/builders/build.hpp"
#include "hbvh/geometry/overlap.hpp"
#include "hbvh/query/tandem_traversal.hpp"
#include "hbvh/scene/generate.hpp"

namespace hbvh {
namespace bench {
/// Defined in bench/main.cpp: SkipWithError, and remember to exit non-zero (Google Benchmark exits 0).
void fail(benchmark::State& state, const std::string& message);
}  // namespace bench

namespace {

using Pairs = std::vector<std::pair<std::uint32_t, std::uint32_t>>;

/// Two copies of one generated object and 256 seeded poses of the second copy whose root BVs overlap
/// the first's (the survey's measuring condition), the first copy at the identity; and, per pose, the
/// overlapping primitive pairs by brute force, the answer every method must give.
struct QueryScenario {
    Bvh bvh;
    QueryTree tree;
    std::vector<RigidTransform> poses;
    std::vector<Pairs> expected;
};

/// Every primitive pair tested with overlaps(), the second copy moved by `pose`; ascending.
Pairs brute_force_pairs(std::span<const Primitive> primitives, const RigidTransform& pose) {
    Pairs pairs;
    for (std::uint32_t i = 0; i < primitives.size(); ++i)
        for (std::uint32_t j = 0; j < primitives.size(); ++j)
            if (overlaps(primitives[i].volume, transformed(primitives[j].volume, pose))) pairs.emplace_back(i, j);
    return pairs;
}

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
    std::vector<Pairs> expected;
    for (const RigidTransform& pose : poses) expected.push_back(brute_force_pairs(primitives, pose));
    return {std::move(bvh), std::move(tree), std::move(poses), std::move(expected)};
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
    // One full cycle of poses before timing: every answer checked against brute force (`all`: the same
    // pairs; `first`: a hit exactly when there is one, and a pair that really overlaps), and a checksum
    // of the answers (equal across methods in `all` mode).
    std::uint64_t checksum = 0;
    for (std::size_t p = 0; p < scenario.poses.size(); ++p) {
        const RigidTransform& pose = scenario.poses[p];
        if constexpr (two_level)
            collide_two_level(scenario.tree, identity, scenario.tree, pose, mode, result);
        else
            collide(scenario.tree, identity, scenario.tree, pose, mode, result);
        for (const auto& [i, j] : result.pairs) checksum += 31u * i + j + 1u;
        const Pairs& expected = scenario.expected[p];
        const bool right = mode == CollideMode::all
                               ? result.pairs == expected
                               : result.intersecting == !expected.empty() &&
                                     result.pairs.size() == (expected.empty() ? 0u : 1u) &&
                                     (expected.empty() ||
                                      std::binary_search(expected.begin(), expected.end(), result.pairs.front()));
        if (!right) {
            bench::fail(state, "wrong answer at pose " + std::to_string(p) + ": " +
                                   std::to_string(result.pairs.size()) + " pairs, brute force finds " +
                                   std::to_string(expected.size()));
            return;
        }
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
                const Algorithm algorithm = info.algorithm();
                benchmark::RegisterBenchmark(("tandem/" + std::string(info.name) + suffix).c_str(),
                                             [count, algorithm, mode](benchmark::State& state) {
                                                 run_queries<false>(state, scenario_for(count, algorithm), mode);
                                             });
            }
            const Algorithm baseline_tree = algorithms().front().algorithm();
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
