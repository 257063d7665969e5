// SPDX-License-Identifier: MIT
// No quadratic path in fitting: fit_best and the two-level build (one fit_best over every primitive's
// generating spheres, gathered by FitInput) over 10^4, 10^5 and 10^6 inputs. A benchmark fails the run
// (hbvh_bench exits 1) when its time grows more than twice as fast as n log n from 10^4 to 10^6.
//
//   hbvh_bench --benchmark_filter='fit_scaling'
//
// Counters: seconds at each size (the fastest of a few runs for the small sizes, one run at 10^6) and
// growth_vs_nlogn = (t(10^6) / t(10^4)) / (10^6 log 10^6 / (10^4 log 10^4)); above 2 is a failure.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "hbvh/builders/build.hpp"
#include "hbvh/fit/fit.hpp"
#include "hbvh/scene/generate.hpp"
#include "hbvh/tree/validate.hpp"

namespace hbvh::bench {
void fail(benchmark::State& state, const std::string& message);
}  // namespace hbvh::bench

namespace hbvh {
namespace {

constexpr double allowed_growth = 2.0;  ///< slack over n log n between the smallest and largest size
constexpr std::uint32_t sizes[] = {10'000, 100'000, 1'000'000};

/// One size of a scenario: prepares its input (untimed), then returns a run that does the timed work and
/// says whether the answer was right.
using Scenario = std::function<std::function<bool()>(std::uint32_t count)>;

/// Spheres of radius 0.1 to 1 uniformly in a ball whose volume grows with the count (constant density).
std::vector<Sphere> ball_of_spheres(std::uint32_t count) {
    SplitMix64 rng(31);
    const double radius = std::cbrt(static_cast<double>(count));
    std::vector<Sphere> spheres;
    spheres.reserve(count);
    while (spheres.size() < count) {
        const Vec3 p(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
        if (p.squaredNorm() <= 1.0) spheres.push_back({radius * p, rng.uniform(0.1, 1.0)});
    }
    return spheres;
}

/// A flat, tilted ring: every centre lies on the 2-D hull of the set's projection, the worst case for the
/// face-flush frames and the capsule bound (quadratic in the hull size before rotating calipers).
std::vector<Sphere> ring_of_spheres(std::uint32_t count) {
    const Mat3 frame = SplitMix64(5).rotation();
    std::vector<Sphere> spheres;
    spheres.reserve(count);
    for (std::uint32_t i = 0; i < count; ++i) {
        const double t = 2.0 * std::numbers::pi * static_cast<double>(i) / static_cast<double>(count);
        spheres.push_back({frame * Vec3(100.0 * std::cos(t), 100.0 * std::sin(t), 0.0), 0.5});
    }
    return spheres;
}

bool encloses(const BoundingVolume& bv, std::span<const Sphere> spheres) {
    return std::all_of(spheres.begin(), spheres.end(), [&](const Sphere& s) { return contains(bv, s, 1e-9); });
}

Scenario fit_best_over(std::vector<Sphere> (*make)(std::uint32_t)) {
    return [make](std::uint32_t count) -> std::function<bool()> {
        auto spheres = std::make_shared<std::vector<Sphere>>(make(count));
        return [spheres] { return encloses(fit_best(*spheres, VolumePolicy{}), *spheres); };
    };
}

/// The two-level build of `hbvh build -a two-level` on a `hbvh generate --seed 1` scene.
std::function<bool()> two_level_build(std::uint32_t count) {
    SceneOptions options;
    options.count = count;
    options.seed = 1;
    auto primitives = std::make_shared<std::vector<Primitive>>(generate_scene(options));
    return [primitives] {
        const Result<Bvh> built = build(*primitives, Algorithm::two_level);
        return built.has_value() && validate(built.value()).has_value();
    };
}

void fit_scaling(benchmark::State& state, const Scenario& scenario) {
    std::vector<double> seconds;
    for (auto _ : state) {
        seconds.clear();
        for (const std::uint32_t count : sizes) {
            const std::function<bool()> run = scenario(count);
            // The small sizes take milliseconds, where one run is noise: keep the fastest of a few.
            const int repeats = count < 1'000'000 ? 5 : 1;
            double best = 0.0;
            for (int r = 0; r < repeats; ++r) {
                const auto start = std::chrono::steady_clock::now();
                const bool right = run();
                const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
                if (!right) {
                    bench::fail(state, "wrong answer at " + std::to_string(count));
                    return;
                }
                best = r == 0 ? elapsed : std::min(best, elapsed);
            }
            seconds.push_back(best);
            state.counters["seconds_" + std::to_string(count)] = best;
        }
    }
    const auto n_log_n = [](double n) { return n * std::log(n); };
    const double growth = (seconds.back() / seconds.front()) / (n_log_n(sizes[2]) / n_log_n(sizes[0]));
    state.counters["growth_vs_nlogn"] = growth;
    if (!(growth <= allowed_growth))
        bench::fail(state, "time grows faster than n log n: " + std::to_string(growth) + "x of it from 10^4 to 10^6");
}

BENCHMARK_CAPTURE(fit_scaling, fit_best_ball, fit_best_over(ball_of_spheres))->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK_CAPTURE(fit_scaling, fit_best_ring, fit_best_over(ring_of_spheres))->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK_CAPTURE(fit_scaling, two_level, Scenario(two_level_build))->Unit(benchmark::kSecond)->Iterations(1);

}  // namespace
}  // namespace hbvh
