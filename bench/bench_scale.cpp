// SPDX-License-Identifier: MIT
// The scale builder on big generated scenes: build time at 20 000 and 10^6 primitives, and its Eq. 2 cost
// against merge and split at 20 000 (counters cost_ratio_vs_*; below 1 means scale is cheaper).
//
//   hbvh_bench --benchmark_filter='scale_build/20k'      (three iterations, then merge and split once)
//   hbvh_bench --benchmark_filter='scale_build/1M'       (one iteration)
#include <benchmark/benchmark.h>

#include <chrono>

#include "hbvh/builders/build.hpp"
#include "hbvh/scene/generate.hpp"
#include "hbvh/tree/stats.hpp"

namespace hbvh {
namespace {

std::vector<Primitive> big_scene(std::uint32_t count) {
    SceneOptions options;
    options.count = count;
    options.seed = 2024;
    return generate_scene(options);
}

/// Builds with `algorithm` once and returns (seconds, Eq. 2 cost).
std::pair<double, double> timed_cost(std::span<const Primitive> primitives, Algorithm algorithm) {
    const auto start = std::chrono::steady_clock::now();
    Result<Bvh> built = build(primitives, algorithm);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return {seconds, built.has_value() ? cost(built.value()) : 0.0};
}

void scale_build(benchmark::State& state, std::uint32_t count) {
    const std::vector<Primitive> primitives = big_scene(count);
    double scale_cost = 0.0;
    for (auto _ : state) {
        Result<Bvh> built = build(primitives, Algorithm::scale);
        scale_cost = built.has_value() ? cost(built.value()) : 0.0;
        benchmark::DoNotOptimize(scale_cost);
    }
    state.counters["primitives"] = static_cast<double>(primitives.size());
    state.counters["cost"] = scale_cost;
    // The comparison builders run once, outside the timed loop, and only at the small size: merge and
    // split are not meant for 10^6 primitives.
    if (count <= 20'000) {
        for (const auto& [name, algorithm] : {std::pair{"merge", Algorithm::merge}, std::pair{"split", Algorithm::split}}) {
            const auto [seconds, other_cost] = timed_cost(primitives, algorithm);
            state.counters[std::string("cost_ratio_vs_") + name] = other_cost > 0.0 ? scale_cost / other_cost : 0.0;
            state.counters[std::string(name) + "_seconds"] = seconds;
        }
    }
}

BENCHMARK_CAPTURE(scale_build, 20k, 20'000u)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK_CAPTURE(scale_build, 1M, 1'000'000u)->Unit(benchmark::kSecond)->Iterations(1);

}  // namespace
}  // namespace hbvh
