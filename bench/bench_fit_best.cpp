// SPDX-License-Identifier: MIT
// Per-call cost of the fitters on the small inputs builders fit most often: the generating spheres of
// 2, 4, 8 and 16 random primitives. Each iteration fits a fixed batch of seeded sets, so the counters
// (mean volume and geometric-mean volume over the batch) let two versions of the fitters be compared
// for tightness as well as speed. HullSmall times the hull step alone, ours against qhull.
#include <benchmark/benchmark.h>

#include <cmath>
#include <string>
#include <vector>

#include "fit/convex_hull.hpp"
#include "fit/quickhull.hpp"
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

/// The hull step alone on the same batches (HullSmall/<method>/<primitives>): summarize_hull with our quickhull
/// (falling back to qhull where it declines) against qhull alone. Counter declined: the share of the batch's
/// solid sets that the quickhull handed to qhull.
void hull_small(benchmark::State& state, detail::HullMethod method) {
    const std::vector<FitInput> sets = batch(static_cast<std::uint32_t>(state.range(0)));
    std::size_t vertices = 0;
    for (auto _ : state) {
        vertices = 0;
        for (const FitInput& input : sets) vertices += detail::summarize_hull(input.spheres, method).vertices.size();
        benchmark::DoNotOptimize(vertices);
    }
    double solid = 0.0, declined = 0.0;
    for (const FitInput& input : sets) {
        if (!detail::summarize_hull(input.spheres, detail::HullMethod::qhull).is_solid) continue;
        solid += 1.0;
        std::vector<Vec3> points;
        for (const Sphere& s : input.spheres) points.push_back(s.center);
        if (!detail::quickhull(points)) declined += 1.0;
    }
    const double n = static_cast<double>(sets.size());
    state.counters["mean_vertices"] = static_cast<double>(vertices) / n;
    state.counters["declined"] = solid > 0.0 ? declined / solid : 0.0;
    state.counters["per_hull"] = benchmark::Counter(n, benchmark::Counter::kIsIterationInvariantRate |
                                                           benchmark::Counter::kInvert);
}

void register_fit_small_benchmarks() {
    for (const auto& [name, method] : {std::pair{"quickhull", detail::HullMethod::automatic},
                                       std::pair{"qhull", detail::HullMethod::qhull}})
        benchmark::RegisterBenchmark((std::string("HullSmall/") + name).c_str(), hull_small, method)
            ->Arg(2)
            ->Arg(8)
            ->Arg(16)
            ->Arg(64)
            ->Unit(benchmark::kMicrosecond);
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
