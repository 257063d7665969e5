// SPDX-License-Identifier: MIT
// Per-call cost of the fitters on the small inputs builders fit most often: the generating spheres of
// 2, 4, 8 and 16 random primitives. Each iteration fits a fixed batch of seeded sets, so the counters
// (mean volume and geometric-mean volume over the batch) let two versions of the fitters be compared
// for tightness as well as speed.
#include <benchmark/benchmark.h>

#include <cmath>
#include <string>
#include <vector>

#include "hbvh/fit/fit.hpp"
#include "hbvh/scene/generate.hpp"

namespace hbvh {
namespace {

/// Sets per batch: enough that the mean volume is stable, few enough that one iteration stays short.
constexpr std::uint64_t batch_size = 32;

std::vector<FitInput> batch(std::uint32_t primitives) {
    std::vector<FitInput> sets;
    for (std::uint64_t seed = 1; seed <= batch_size; ++seed) {
        SceneOptions options;
        options.count = primitives;
        options.seed = seed;
        FitInput input;
        for (const Primitive& p : generate_scene(options)) input.add(p.volume);
        sets.push_back(std::move(input));
    }
    return sets;
}

enum class Fitter { best, obb, capsule, sphere };

double fit_volume(Fitter fitter, const FitInput& input) {
    switch (fitter) {
        case Fitter::best: return volume(fit_best(input.spheres, VolumePolicy::all(), input.hint_axes));
        case Fitter::obb: return fit_obb(input.spheres, input.hint_axes).volume();
        case Fitter::capsule: return fit_capsule(input.spheres, input.hint_axes).volume();
        case Fitter::sphere: return fit_sphere(input.spheres).volume();
    }
    return 0.0;
}

void fit_small(benchmark::State& state, Fitter fitter) {
    const std::vector<FitInput> sets = batch(static_cast<std::uint32_t>(state.range(0)));
    double sum = 0.0, log_sum = 0.0, spheres = 0.0;
    for (auto _ : state) {
        sum = 0.0, log_sum = 0.0, spheres = 0.0;
        for (const FitInput& input : sets) {
            const double v = fit_volume(fitter, input);
            sum += v;
            log_sum += std::log(v);
            spheres += static_cast<double>(input.spheres.size());
        }
        benchmark::DoNotOptimize(sum);
    }
    const double n = static_cast<double>(sets.size());
    state.counters["mean_volume"] = sum / n;
    state.counters["geomean_volume"] = std::exp(log_sum / n);
    state.counters["mean_spheres"] = spheres / n;
    // Time per single fit, not per batch.
    state.counters["per_fit"] = benchmark::Counter(n, benchmark::Counter::kIsIterationInvariantRate |
                                                          benchmark::Counter::kInvert);
}

void register_fit_small_benchmarks() {
    const std::pair<const char*, Fitter> fitters[] = {
        {"best", Fitter::best}, {"obb", Fitter::obb}, {"capsule", Fitter::capsule}, {"sphere", Fitter::sphere}};
    for (const auto& [name, fitter] : fitters)
        benchmark::RegisterBenchmark((std::string("FitSmall/") + name).c_str(), fit_small, fitter)
            ->Arg(2)
            ->Arg(4)
            ->Arg(8)
            ->Arg(16)
            ->Unit(benchmark::kMicrosecond);
}

const bool fit_small_benchmarks_registered = (register_fit_small_benchmarks(), true);

}  // namespace
}  // namespace hbvh
