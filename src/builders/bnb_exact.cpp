// SPDX-License-Identifier: MIT
// bnb-exact: rich candidates (Tightest ∪ Enlarge ∪ kNN) and solve_exact in the bottom-up driver.
//
// Per level the solver is exact and the candidate set contains Enlarge's, so each level's choice costs
// no more than B&B-Enlarge's would on the same level. Later levels differ, though, so that alone does not
// bound the whole tree; guarantee_enlarge builds bnb-enlarge as well and keeps the cheaper (docs/solver.md §3).
#include "hbvh/builders/bnb_exact.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "candidates.hpp"
#include "guarded_build.hpp"
#include "rich_candidates.hpp"
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

namespace {
/// The solvers may finish their (small) budgets without noticing that the deadline passed; the tree is
/// then the best found in the time there was, which the report must say.
void note_if_late(const BuildContext& context) {
    if (context.expired())
        context.note_deadline("bnb-exact: the time limit passed during the build; each level kept the best "
                              "partition its solver found in its share");
}
}  // namespace

Result<Bvh> build_bnb_exact(std::span<const Primitive> primitives, const BuildContext& context,
                            const BnbExactOptions& options) {
    // The deadline becomes solver budgets, and once it has passed the driver puts one root over the levels
    // built so far (so the guard's checkpoint never throws: it gets no deadline and only reports progress).
    BuildContext progress_only = context;
    progress_only.deadline = BuildContext::Clock::time_point::max();
    return detail::guarded_build(primitives, progress_only, "bnb-exact", static_cast<double>(primitives.size()),
                                 [&](const detail::Checkpoint& checkpoint) {
        BnbExactOptions within = options;
        if (context.has_deadline()) {
            const double calls = 2.0 * std::max(1.0, std::log2(static_cast<double>(primitives.size())));
            const double share = std::max(context.seconds_left(), 1e-9) / calls;
            within.budget.max_seconds = 0.5 * share;
            within.enlarge_options.budget.max_seconds = 0.5 * share;
        }
        const std::uint32_t k = within.nearest_neighbours;
        // The driver's checkpoint: the real deadline (for its anytime root), this guard's progress.
        BuildContext level_context = context;
        BuildReport exact_report;
        level_context.report = context.report != nullptr ? &exact_report : nullptr;
        const detail::Checkpoint levels(level_context, static_cast<double>(primitives.size()));
        (void)checkpoint;
        BuildReport* report = context.report;
        Bvh exact = build_bottom_up(
            primitives, context.policy, [k](const Level& level) { return rich_candidates(level, k); },
            exact_level_solver(), {within.budget, report != nullptr ? &exact_report : nullptr, &levels});
        if (within.guarantee_enlarge) {
            BuildReport enlarge_report;
            BuildContext enlarge_context = progress_only;
            enlarge_context.deadline = context.deadline;
            enlarge_context.report = report != nullptr ? &enlarge_report : nullptr;
            enlarge_context.progress = nullptr;
            Result<Bvh> enlarge = build_bnb_enlarge(primitives, enlarge_context, within.enlarge_options);
            if (!enlarge) return enlarge;
            if (cost(*enlarge, context.policy) < cost(exact, context.policy)) {
                if (report != nullptr) {
                    *report = std::move(enlarge_report);
                    report->notes.push_back("bnb-exact: bnb-enlarge's tree was cheaper and is returned");
                }
                note_if_late(context);
                return enlarge;
            }
        }
        if (report != nullptr) *report = std::move(exact_report);
        note_if_late(context);
        return Result<Bvh>(std::move(exact));
    });
}

}  // namespace hbvh
