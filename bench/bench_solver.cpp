// SPDX-License-Identifier: MIT
// solve_exact vs the survey's reference branch and bound on the level instances of a Tie-Interceptor-size
// model (27 primitives), and the optimal builder's subset DP at 13/15/17 primitives.
//
// The level instances are those B&B-Enlarge's driver produces on data/models/tie_interceptor.xml (a
// generated 27-primitive scene with a fixed seed if the file is missing).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>

#include "builders/bottom_up.hpp"
#include "builders/candidates.hpp"
#include "builders/optimal_plan.hpp"
#include "builders/set_partition.hpp"
#include "hbvh/builders/bnb_enlarge.hpp"
#include "hbvh/builders/bnb_exact.hpp"
#include "hbvh/builders/optimal.hpp"
#include "hbvh/fit/fit.hpp"
#include "hbvh/io/xml.hpp"
#include "hbvh/scene/generate.hpp"
#include "hbvh/tree/stats.hpp"

namespace hbvh {
namespace {

struct LevelInstance {
    std::uint32_t node_count = 0;
    std::vector<Candidate> candidates;
    std::vector<double> node_volumes;
};

/// The model: data/models/tie_interceptor.xml (27 primitives), or a generated 27-primitive scene if absent.
std::vector<Primitive> tie_model() {
    const Result<XmlModel> model = read_xml_file(std::filesystem::path(HBVH_SOURCE_DIR) / "data/models/tie_interceptor.xml");
    if (model.has_value()) return model->primitives;
    return generate_scene({.count = 27, .seed = 27});
}

/// Runs B&B-Enlarge's levels (library Enlarge generator, bottom-up driver) with solve_exact and records
/// every level's instance exactly as the driver hands it to the solver.
const std::vector<LevelInstance>& tie_levels() {
    static const std::vector<LevelInstance> levels = [] {
        std::vector<LevelInstance> out;
        const auto primitives = tie_model();
        const LevelSolver recording = [&out](std::uint32_t node_count, std::span<const Candidate> candidates,
                                             std::span<const double> node_volumes, const SolverBudget& budget) {
            out.push_back({node_count, {candidates.begin(), candidates.end()}, {node_volumes.begin(), node_volumes.end()}});
            return solve_exact(node_count, candidates, budget);
        };
        const Bvh bvh = build_bottom_up(primitives, VolumePolicy::all(),
                                        [](const Level& level) { return enlarge_candidates(level); }, recording);
        benchmark::DoNotOptimize(bvh);
        return out;
    }();
    return levels;
}

void BM_solve_exact(benchmark::State& state) {
    const auto& levels = tie_levels();
    std::uint64_t nodes = 0;
    for (auto _ : state) {
        nodes = 0;
        for (const LevelInstance& level : levels) {
            auto p = solve_exact(level.node_count, level.candidates);
            benchmark::DoNotOptimize(p);
            nodes += p ? p->nodes_explored : 0;
        }
    }
    state.counters["levels"] = static_cast<double>(levels.size());
    state.counters["solver_nodes"] = static_cast<double>(nodes);
}
BENCHMARK(BM_solve_exact)->Unit(benchmark::kMillisecond);

/// One level at a time (argument: level index), so a level the reference cannot finish does not hide the
/// others. The reference gets a 10 s budget per level.
void BM_solve_exact_level(benchmark::State& state) {
    const auto& levels = tie_levels();
    const auto index = static_cast<std::size_t>(state.range(0));
    if (index >= levels.size()) {
        state.SkipWithError("no such level");
        return;
    }
    const LevelInstance& level = levels[index];
    for (auto _ : state) benchmark::DoNotOptimize(solve_exact(level.node_count, level.candidates));
    state.counters["nodes"] = level.node_count;
}
BENCHMARK(BM_solve_exact_level)->DenseRange(0, 5)->Unit(benchmark::kMillisecond);

void BM_solve_reference_level(benchmark::State& state) {
    const auto& levels = tie_levels();
    const auto index = static_cast<std::size_t>(state.range(0));
    if (index >= levels.size()) {
        state.SkipWithError("no such level");
        return;
    }
    const LevelInstance& level = levels[index];
    bool budget_hit = false;
    for (auto _ : state) {
        auto p = solve_reference_branch_and_bound(level.node_count, level.candidates, level.node_volumes,
                                                  SolverBudget{0, 10.0});
        budget_hit = !p || p->budget_hit;
        benchmark::DoNotOptimize(p);
    }
    state.counters["nodes"] = level.node_count;
    state.counters["budget_hit"] = budget_hit ? 1.0 : 0.0;
}
BENCHMARK(BM_solve_reference_level)->DenseRange(0, 5)->Unit(benchmark::kMillisecond)->Iterations(1);

/// Per-level comparison printed once: candidates, costs of both solvers, solver nodes.
void BM_level_table(benchmark::State& state) {
    for (auto _ : state) {
        for (const LevelInstance& level : tie_levels()) {
            const auto e = solve_exact(level.node_count, level.candidates);
            const auto r = solve_reference_branch_and_bound(level.node_count, level.candidates, level.node_volumes,
                                                            SolverBudget{0, 10.0});
            std::printf("level nodes=%u candidates=%zu exact_cost=%.6f exact_nodes=%llu reference_cost=%.6f reference_nodes=%llu%s\n",
                        level.node_count, level.candidates.size(), e ? e->cost : -1.0,
                        static_cast<unsigned long long>(e ? e->nodes_explored : 0), r ? r->cost : -1.0,
                        static_cast<unsigned long long>(r ? r->nodes_explored : 0), r && r->budget_hit ? " (budget hit)" : "");
        }
    }
}
BENCHMARK(BM_level_table)->Iterations(1);

/// bnb-exact's rich candidates + exact solver alone (no bnb-enlarge guarantee) vs bnb-enlarge on the model.
void BM_rich_vs_enlarge(benchmark::State& state) {
    const auto primitives = tie_model();
    for (auto _ : state) {
        BnbExactOptions alone;
        alone.guarantee_enlarge = false;
        const double rich = cost(build_bnb_exact(primitives, BuildContext{}, alone).value());
        const double enlarge = cost(build_bnb_enlarge(primitives, BuildContext{}).value());
        state.counters["rich_cost"] = rich;
        state.counters["enlarge_cost"] = enlarge;
        state.counters["ratio"] = rich / enlarge;
    }
}
BENCHMARK(BM_rich_vs_enlarge)->Unit(benchmark::kMillisecond)->Iterations(1);

/// The optimal builder's DP alone, on a synthetic AABB-like volume function (fitting excluded).
void BM_optimal_dp(benchmark::State& state) {
    const auto n = static_cast<std::uint32_t>(state.range(0));
    SplitMix64 rng(n);
    std::vector<Aabb> boxes;
    for (std::uint32_t i = 0; i < n; ++i) {
        const Vec3 c(rng.uniform(0, 10), rng.uniform(0, 10), rng.uniform(0, 10));
        boxes.push_back({c - Vec3::Constant(0.5), c + Vec3::Constant(0.5)});
    }
    std::vector<double> volume(std::size_t{1} << n, 0.0);
    std::vector<Aabb> unions(std::size_t{1} << n, Aabb::empty());
    for (std::uint32_t s = 1; s < (1u << n); ++s) {
        const std::uint32_t low = static_cast<std::uint32_t>(std::countr_zero(s));
        unions[s] = unions[s & (s - 1)].merged(boxes[low]);
        volume[s] = unions[s].volume();
    }
    for (auto _ : state) benchmark::DoNotOptimize(solve_optimal_hierarchy(n, volume));
}
BENCHMARK(BM_optimal_dp)->Arg(13)->Arg(15)->Arg(17)->Arg(18)->Unit(benchmark::kMillisecond)->Iterations(1);

/// The whole optimal build (fitting included) with AABB+sphere and with every kind.
void BM_optimal_build(benchmark::State& state) {
    const auto n = static_cast<std::uint32_t>(state.range(0));
    const auto primitives = generate_scene({.count = n, .seed = 3});
    VolumePolicy policy = VolumePolicy::all();
    if (state.range(1) == 0) policy.allowed = {true, false, true, false};
    BuildContext context;
    context.policy = policy;
    for (auto _ : state) benchmark::DoNotOptimize(build_optimal(primitives, context));
}
// {n, 1}: every kind, where subsets are fitted on demand (docs/solver.md §2); issue 14 asks for 18 in 1 s.
BENCHMARK(BM_optimal_build)
    ->Args({13, 0})
    ->Args({15, 0})
    ->Args({17, 0})
    ->Args({13, 1})
    ->Args({17, 1})
    ->Args({18, 1})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

}  // namespace
}  // namespace hbvh

