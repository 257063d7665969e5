// SPDX-License-Identifier: MIT
// bnb-exact: rich candidates (Tightest ∪ Enlarge ∪ kNN) and solve_exact in the bottom-up driver.
//
// Per level the solver is exact and the candidate set contains Enlarge's, so each level's choice costs
// no more than B&B-Enlarge's would on the same level. Later levels differ, though, so that alone does not
// bound the whole tree; guarantee_enlarge builds bnb-enlarge as well and keeps the cheaper (docs/solver.md §3).
#include "hbvh/build/bnb_exact.hpp"

#include <algorithm>
#include <numeric>

#include "hbvh/build/candidates.hpp"
#include "hbvh/tree/stats.hpp"

namespace hbvh {

std::vector<std::vector<std::uint32_t>> rich_candidates(const Level& level, std::uint32_t nearest_neighbours) {
    std::vector<std::vector<std::uint32_t>> sets = tightest_candidates(level);
    std::vector<std::vector<std::uint32_t>> enlarge = enlarge_candidates(level);
    sets.insert(sets.end(), std::make_move_iterator(enlarge.begin()), std::make_move_iterator(enlarge.end()));

    // k nearest neighbours by centre distance; brute force is O(n^2 log n), fine for the levels a
    // set-partition solver can take (hundreds of nodes).
    const std::uint32_t n = level.size();
    const std::uint32_t max_size = enlarge_max_group_size(n);
    std::vector<Vec3> centres;
    for (const LevelNode& node : level.nodes()) centres.push_back(world_aabb(node.volume).center());
    std::vector<std::uint32_t> order;
    for (std::uint32_t i = 0; i < n; ++i) {
        order.resize(n);
        std::iota(order.begin(), order.end(), 0u);
        order.erase(order.begin() + i);
        const std::uint32_t k = std::min<std::uint32_t>(nearest_neighbours, n - 1);
        std::partial_sort(order.begin(), order.begin() + k, order.end(), [&](std::uint32_t a, std::uint32_t b) {
            const double da = (centres[a] - centres[i]).squaredNorm();
            const double db = (centres[b] - centres[i]).squaredNorm();
            return da < db || (da == db && a < b);
        });
        std::vector<std::uint32_t> prefix{i};
        for (std::uint32_t t = 0; t < k; ++t) {
            sets.push_back({i, order[t]});
            if (prefix.size() < max_size) {
                prefix.push_back(order[t]);
                sets.push_back(prefix);
            }
        }
    }
    return sets;  // the driver sorts, deduplicates and drops singletons
}

LevelSolver exact_level_solver() {
    return [](std::uint32_t node_count, std::span<const Candidate> candidates, std::span<const double>,
              const SolverBudget& budget) { return solve_exact(node_count, candidates, budget); };
}

Bvh build_bnb_exact(std::span<const Primitive> primitives, const VolumePolicy& policy,
                    const ExactBottomUpOptions& options, BuildReport* report) {
    const std::uint32_t k = options.nearest_neighbours;
    BuildReport exact_report;
    Bvh exact = build_bottom_up(
        primitives, policy, [k](const Level& level) { return rich_candidates(level, k); }, exact_level_solver(),
        {options.budget, report != nullptr ? &exact_report : nullptr});
    if (options.guarantee_enlarge) {
        BuildReport enlarge_report;
        Bvh enlarge = build_bnb_enlarge(primitives, policy, options.enlarge_options,
                                        report != nullptr ? &enlarge_report : nullptr);
        if (cost(enlarge, policy) < cost(exact, policy)) {
            if (report != nullptr) {
                *report = std::move(enlarge_report);
                report->notes.push_back("bnb-exact: bnb-enlarge's tree was cheaper and is returned");
            }
            return enlarge;
        }
    }
    if (report != nullptr) *report = std::move(exact_report);
    return exact;
}

}  // namespace hbvh
