// SPDX-License-Identifier: MIT
// solve_exact vs the survey's reference branch and bound on the level instances of a Tie-Interceptor-size
// model (27 primitives), and the optimal builder's subset DP at 13/15/17 primitives.
//
// Until data/models/tie_interceptor.xml and the bnb branch's Enlarge generator are on this branch, the
// model is a generated 27-primitive scene (fixed seed) and candidates come from a local Enlarge-style
// generator (survey §3, Figure 11): grow each node's world AABB by 5 % steps until it touches `want`
// others, then every subset of the node and those others with 2..lg(n) members.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <optional>

#include "hbvh/build/optimal.hpp"
#include "hbvh/build/set_partition.hpp"
#include "hbvh/fit/fit.hpp"
#include "hbvh/scene/generate.hpp"

namespace hbvh {
namespace {

struct LevelInstance {
    std::uint32_t node_count = 0;
    std::vector<Candidate> candidates;
    std::vector<double> node_volumes;
};

bool touches(const Aabb& a, const Aabb& b) {
    return (a.min.array() <= b.max.array()).all() && (b.min.array() <= a.max.array()).all();
}

/// Enlarge-style candidates for one level; `groups[j]` = primitives under node j.
std::vector<Candidate> enlarge_candidates(const std::vector<Primitive>& primitives,
                                          const std::vector<std::vector<std::uint32_t>>& groups,
                                          const VolumePolicy& policy, std::uint32_t want) {
    const auto n = static_cast<std::uint32_t>(groups.size());
    std::vector<Aabb> boxes(n);
    for (std::uint32_t j = 0; j < n; ++j) {
        Aabb box = Aabb::empty();
        for (std::uint32_t p : groups[j]) box = box.merged(world_aabb(primitives[p].volume));
        boxes[j] = box;
    }
    const std::uint32_t max_size = std::max(2u, static_cast<std::uint32_t>(std::floor(std::log2(n))));
    std::vector<std::vector<std::uint32_t>> member_sets;
    for (std::uint32_t a = 0; a < n; ++a) {
        std::vector<std::uint32_t> hits;
        for (double scale = 1.05; hits.size() < std::min(want, n - 1); scale *= 1.05) {
            const Vec3 c = boxes[a].center();
            const Vec3 h = boxes[a].half_extents() * scale + Vec3::Constant(1e-9 * scale);
            const Aabb grown{c - h, c + h};
            hits.clear();
            for (std::uint32_t b = 0; b < n; ++b)
                if (b != a && touches(grown, boxes[b])) hits.push_back(b);
        }
        const auto k = static_cast<std::uint32_t>(std::min<std::size_t>(hits.size(), 12));
        for (std::uint32_t pick = 1; pick < (1u << k); ++pick) {
            if (static_cast<std::uint32_t>(std::popcount(pick)) + 1 > max_size) continue;
            std::vector<std::uint32_t> m{a};
            for (std::uint32_t i = 0; i < k; ++i)
                if (pick >> i & 1u) m.push_back(hits[i]);
            std::sort(m.begin(), m.end());
            member_sets.push_back(std::move(m));
        }
    }
    std::sort(member_sets.begin(), member_sets.end());
    member_sets.erase(std::unique(member_sets.begin(), member_sets.end()), member_sets.end());
    std::vector<Candidate> candidates;
    for (auto& m : member_sets) {
        FitInput input;
        for (std::uint32_t j : m)
            for (std::uint32_t p : groups[j]) input.add(primitives[p].volume);
        const double cost = static_cast<double>(m.size()) * policy.weighted_volume(fit_best(input.spheres, policy, input.hint_axes));
        candidates.push_back({std::move(m), cost});
    }
    return candidates;
}

/// Runs the bottom-up levels with solve_exact and records every level's instance.
const std::vector<LevelInstance>& tie_levels() {
    static const std::vector<LevelInstance> levels = [] {
        const VolumePolicy policy = VolumePolicy::all();
        const auto primitives = generate_scene({.count = 27, .seed = 27});
        std::vector<std::vector<std::uint32_t>> groups;
        for (std::uint32_t i = 0; i < primitives.size(); ++i) groups.push_back({i});
        std::vector<LevelInstance> out;
        while (groups.size() > 1) {
            LevelInstance level;
            level.node_count = static_cast<std::uint32_t>(groups.size());
            level.candidates = enlarge_candidates(primitives, groups, policy, 3);
            for (const auto& g : groups) {
                FitInput input;
                for (std::uint32_t p : g) input.add(primitives[p].volume);
                level.node_volumes.push_back(policy.weighted_volume(fit_best(input.spheres, policy, input.hint_axes)));
            }
            std::optional<Partition> p = solve_exact(level.node_count, level.candidates);
            if (!p) {
                // No exact cover among the candidates: carry each node up alone (cost of a lone child).
                for (std::uint32_t j = 0; j < level.node_count; ++j) level.candidates.push_back({{j}, 2.0 * level.node_volumes[j]});
                p = solve_exact(level.node_count, level.candidates);
            }
            std::vector<std::vector<std::uint32_t>> next;
            for (std::uint32_t c : p->chosen) {
                std::vector<std::uint32_t> merged;
                for (std::uint32_t j : level.candidates[c].members) merged.insert(merged.end(), groups[j].begin(), groups[j].end());
                next.push_back(std::move(merged));
            }
            out.push_back(std::move(level));
            if (next.size() == groups.size()) break;  // no progress possible
            groups = std::move(next);
        }
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
BENCHMARK(BM_solve_exact_level)->DenseRange(0, 3)->Unit(benchmark::kMillisecond);

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
BENCHMARK(BM_solve_reference_level)->DenseRange(0, 3)->Unit(benchmark::kMillisecond)->Iterations(1);

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
BENCHMARK(BM_optimal_dp)->Arg(13)->Arg(15)->Arg(17)->Unit(benchmark::kMillisecond)->Iterations(1);

/// The whole optimal build (fitting included) with AABB+sphere and with every kind.
void BM_optimal_build(benchmark::State& state) {
    const auto n = static_cast<std::uint32_t>(state.range(0));
    const auto primitives = generate_scene({.count = n, .seed = 3});
    VolumePolicy policy = VolumePolicy::all();
    if (state.range(1) == 0) policy.allowed = {true, false, true, false};
    for (auto _ : state) benchmark::DoNotOptimize(build_optimal(primitives, policy));
}
BENCHMARK(BM_optimal_build)->Args({13, 0})->Args({15, 0})->Args({17, 0})->Args({13, 1})->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace
}  // namespace hbvh

BENCHMARK_MAIN();
