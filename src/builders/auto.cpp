// SPDX-License-Identifier: MIT
#include "hbvh/builders/auto.hpp"

#include <algorithm>
#include <atomic>
#include <mutex>
#include <numeric>
#include <optional>
#include <string>
#include <vector>

#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include "guarded_build.hpp"
#include "report_text.hpp"
#include "treelet_fit_cache.hpp"
#include "../tree/collapse.hpp"
#include "hbvh/builders/binned.hpp"
#include "hbvh/builders/insertion.hpp"
#include "hbvh/builders/insertion_haber.hpp"
#include "hbvh/builders/build.hpp"
#include "hbvh/assert.hpp"
#include "hbvh/tree/stats.hpp"

namespace hbvh {
namespace {

/// One member's outcome: its (refined) tree, cost and report, or its error, or nothing when it was skipped.
struct MemberOutcome {
    std::optional<Result<Bvh>> tree;
    double cost = 0.0;
    std::string costs;  ///< "name cost" or "name cost -> refined cost", for the report
    BuildReport report;
    TreeletReport treelets;
};

/// A member's tree. binned's net against split is off: up to its limit split is in the same portfolio, so the
/// net would only build split's tree a second time.
/// The insertions' exact refits are capped (auto_insertion_refit_budget): on input sorted along a line they build
/// a chain, and their refits grow cubically with n.
Result<Bvh> build_member(std::span<const Primitive> primitives, Algorithm algorithm, const BuildContext& context) {
    if (algorithm == Algorithm::binned) {
        BinnedOptions options;
        options.guarantee_split_up_to = 0;
        return build_binned(primitives, context, options);
    }
    if (algorithm == Algorithm::insertion) {
        InsertionOptions options;
        options.max_refit_primitives = auto_insertion_refit_budget(primitives.size());
        return build_insertion(primitives, context, options);
    }
    if (algorithm == Algorithm::insertion_haber) {
        InsertionHaberOptions options;
        options.max_refit_primitives = auto_insertion_refit_budget(primitives.size());
        return build_insertion_haber(primitives, context, options);
    }
    return build(primitives, algorithm, context);
}

/// How many of the members' trees are refined before the comparison, the cheapest unrefined ones first.
std::size_t members_to_refine(std::size_t primitive_count, std::size_t member_count, const AutoOptions& options) {
    if (primitive_count <= auto_refine_each_max_primitives) return member_count;
    if (primitive_count <= auto_refine_max_primitives) return std::min<std::size_t>(auto_refine_cheapest_members, member_count);
    return options.refine_always ? 1 : 0;
}

/// Where only the `refined` cheapest unrefined trees are refined, which ones is known only when every member has
/// built, yet some are certain sooner: a member is among them once enough finished members rank after it
/// (costlier, or as costly and later in the list, as the final ranking breaks ties), since then no costs of the
/// unfinished ones can push it out. Its refinement then starts at once instead of after the slowest build. The
/// same trees are refined, so every tree is the same; only the refinements start sooner (docs/treelets.md §4).
class EarlyRefinements {
public:
    EarlyRefinements(std::size_t members, std::size_t refined)
        : finished_(members, false), claimed_(members, false), costs_(members, 0.0),
          ranked_after_needed_(members - std::min(refined, members)) {}

    /// Records that member `m` built a tree of cost `cost`, and returns the members now certain to be refined
    /// that no worker has taken yet, taken for the caller.
    std::vector<std::size_t> finish(std::size_t m, double cost) {
        const std::scoped_lock lock(mutex_);
        finished_[m] = true;
        costs_[m] = cost;
        std::vector<std::size_t> taken;
        if (ranked_after_needed_ == finished_.size()) return taken;  // nothing is refined
        for (std::size_t i = 0; i < finished_.size(); ++i) {
            if (!finished_[i] || claimed_[i]) continue;
            std::size_t ranked_after = 0;
            for (std::size_t j = 0; j < finished_.size(); ++j)
                if (j != i && finished_[j] && (costs_[j] > costs_[i] || (costs_[j] == costs_[i] && j > i))) ++ranked_after;
            if (ranked_after >= ranked_after_needed_) {
                claimed_[i] = true;
                taken.push_back(i);
            }
        }
        return taken;
    }

    /// Whether member `m`'s refinement was taken by a worker (read once the workers are done).
    [[nodiscard]] bool taken(std::size_t m) const { return claimed_[m]; }

private:
    std::mutex mutex_;
    std::vector<bool> finished_, claimed_;
    std::vector<double> costs_;
    std::size_t ranked_after_needed_;
};

/// `auto`: every member of auto_portfolio(n) builds a tree, the cheapest few under Eq. 2 are refined
/// (members_to_refine: all of them up to auto_refine_each_max_primitives, since refinement from different starts
/// ends in different local optima, docs/treelets.md §3), and the cheapest refined tree wins (first in the list on
/// ties). The members build, and then refine, in parallel (each is a function of the primitives alone, and the
/// trees to refine and the winner are chosen in list order afterwards, so the result does not depend on the
/// thread count or on which finishes first).
Result<Bvh> auto_tree(std::span<const Primitive> primitives, const BuildContext& context, const AutoOptions& options) {
    const std::vector<Algorithm> members = auto_portfolio(primitives.size());
    const std::size_t refined_count =
        members.front() == Algorithm::optimal ? 0 : members_to_refine(primitives.size(), members.size(), options);
    const bool limited = context.has_deadline();
    // The members' trees are over the same primitives and refined under the same policy, and their
    // treelets cover many of the same sets: one cache fits each set once for all of them.
    detail::TreeletFitCache fits(primitives.size());
    std::vector<MemberOutcome> outcomes(members.size());
    const auto refine_member = [&](MemberOutcome& outcome) {
        **outcome.tree = detail::refine_treelets_cached(**outcome.tree, context.policy,
                                                        treelets_within(context, options.treelets), fits, &outcome.treelets);
        outcome.cost = outcome.treelets.cost_after;
        outcome.costs += " -> " + detail::format_cost(outcome.cost);
    };
    // Where every member is refined, each refines its tree as soon as it is built, without waiting for the
    // others' builds (a refinement depends on its tree only, so the trees are the same).
    const bool refine_each = refined_count >= members.size();
    EarlyRefinements early(members.size(), refined_count);
    const auto run_member = [&](std::size_t m) {
        // Under a time limit the members share it: each gets what is left (and stops at its own checks), and
        // once nothing is left the rest are skipped (the first always runs, so there is a tree).
        if (m > 0 && limited && context.expired()) return;
        MemberOutcome& outcome = outcomes[m];
        BuildContext member_context = context;
        member_context.report = context.report != nullptr ? &outcome.report : nullptr;
        member_context.progress = nullptr;  // auto reports per member instead
        Result<Bvh> built = build_member(primitives, members[m], member_context);
        if (built) {
            outcome.cost = cost(*built, context.policy);
            outcome.costs = std::string(to_string(members[m])) + " " + detail::format_cost(outcome.cost);
        }
        outcome.tree = std::move(built);
        if (!*outcome.tree) return;
        if (refine_each) {
            refine_member(outcome);
            return;
        }
        for (const std::size_t certain : early.finish(m, outcome.cost)) refine_member(outcomes[certain]);
    };
    // Each free worker takes the next member: a member's build and refinement take from one to tens of
    // milliseconds, depending on what the shared cache already holds, and parallel_for's fixed halves of the
    // list left one core idle for 10-15 ms at the end (the cannon, the Tie-Interceptor). The two slow builders
    // go first, so that neither is what a core waits for at the end (docs/treelets.md §4). Which worker runs a
    // member, and when, changes no tree.
    std::vector<std::size_t> order(members.size());
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::stable_partition(order.begin(), order.end(), [&](std::size_t m) {
        return members[m] == Algorithm::scale || members[m] == Algorithm::insertion_haber;
    });
    std::atomic<std::size_t> next_member{0};
    const std::size_t workers = std::min<std::size_t>(members.size(), static_cast<std::size_t>(
                                                                           tbb::this_task_arena::max_concurrency()));
    tbb::parallel_for(std::size_t{0}, workers, [&](std::size_t) {
        for (std::size_t k = next_member++; k < members.size(); k = next_member++) run_member(order[k]);
    }, tbb::simple_partitioner());
    // The first error in list order ends the build; else the `refined_count` cheapest trees (list order on ties)
    // are refined.
    std::vector<std::size_t> built;
    for (std::size_t m = 0; m < members.size(); ++m) {
        if (!outcomes[m].tree) continue;
        if (!*outcomes[m].tree) return std::move(*outcomes[m].tree);
        built.push_back(m);
    }
    HBVH_ASSERT(!built.empty());  // the first member always runs
    std::stable_sort(built.begin(), built.end(),
                     [&](std::size_t a, std::size_t b) { return outcomes[a].cost < outcomes[b].cost; });
    const std::size_t refine = std::min(refined_count, built.size());
    if (!refine_each)
        tbb::parallel_for(std::size_t{0}, refine, [&](std::size_t r) {
            if (!early.taken(built[r])) refine_member(outcomes[built[r]]);
        });
    // The callback is called from the calling thread only (BuildContext::progress), so once the members are done.
    context.report_progress(static_cast<double>(members.size()) / static_cast<double>(members.size() + 1));

    // The cheapest tree wins; on equal cost the lower one (fewer levels for a query to descend), then the first
    // in the list. A tiled floor of flat boxes costs 0 whatever the tree, and the first member's was a chain of
    // height n - 1. An unrefined tree is no cheaper than the refined ones (they were the cheapest before
    // refinement, which never adds cost), so only they compete when any is.
    const auto competing_end = built.begin() + static_cast<std::ptrdiff_t>(std::max<std::size_t>(refine, 1));
    std::vector<std::uint32_t> heights(members.size(), 0);
    for (auto it = built.begin(); it != competing_end; ++it) heights[*it] = height(**outcomes[*it].tree);
    const std::size_t winner = *std::min_element(built.begin(), competing_end, [&](std::size_t a, std::size_t b) {
        if (outcomes[a].cost != outcomes[b].cost) return outcomes[a].cost < outcomes[b].cost;
        return heights[a] != heights[b] ? heights[a] < heights[b] : a < b;
    });
    std::string costs;
    std::string skipped;
    for (std::size_t m = 0; m < members.size(); ++m) {
        if (!outcomes[m].tree)
            skipped += (skipped.empty() ? "" : ", ") + std::string(to_string(members[m]));
        else
            costs += (costs.empty() ? "" : ", ") + outcomes[m].costs;
    }
    Bvh best = std::move(**outcomes[winner].tree);
    // Treelets re-group a few units at a time and never dissolve a node into a parent outside the treelet; the
    // exact collapse does, and only lowers the cost (on 300 copies of one sphere, the refined trees were 1.14x the
    // flat one).
    std::size_t dissolved = 0;
    double before_collapse = 0.0;
    if (primitives.size() <= detail::collapse_max_primitives) {
        before_collapse = cost(best, context.policy);
        const std::size_t nodes = best.nodes.size();
        best = detail::collapse_optimally(best, context.policy);
        dissolved = nodes - best.nodes.size();
    }
    const TreeletReport best_treelets = outcomes[winner].treelets;
    if (context.report != nullptr) {
        *context.report = std::move(outcomes[winner].report);
        const std::string kept(to_string(members[winner]));
        if (members.size() > 1)
            context.report->notes.push_back("auto: " + std::to_string(primitives.size()) + " primitives, portfolio " +
                                            costs + "; kept " + kept);
        else
            context.report->notes.push_back("auto: " + std::to_string(primitives.size()) + " primitives, built with " +
                                            kept);
        if (!skipped.empty()) {
            context.report->notes.push_back("auto: time limit reached; skipped " + skipped);
            context.report->budget_hit = true;
        }
        if (refine > 0) note_treelets(*context.report, best_treelets);
        if (dissolved > 0)
            context.report->notes.push_back("auto: the exact collapse dissolved " + std::to_string(dissolved) + " nodes, cost " +
                                            detail::format_cost(before_collapse) + " -> " +
                                            detail::format_cost(cost(best, context.policy)));
    }
    return Result<Bvh>(std::move(best));
}
}  // namespace

Result<Bvh> build_auto(std::span<const Primitive> primitives, const BuildContext& context, const AutoOptions& options) {
    // The members check their input and output themselves; the guard adds the same checks around the
    // whole (cheap, linear) and no deadline of its own: the members and refinements share it.
    BuildContext no_deadline = context;
    no_deadline.deadline = BuildContext::Clock::time_point::max();
    return detail::guarded_build(primitives, no_deadline, "auto", 1.0,
                                 [&](const detail::Checkpoint&) { return auto_tree(primitives, context, options); });
}

std::uint64_t auto_insertion_refit_budget(std::size_t primitive_count) {
    std::uint64_t levels = 1;
    while ((std::uint64_t{1} << levels) < primitive_count) ++levels;
    return auto_insertion_refit_factor * primitive_count * levels;
}

Algorithm auto_choice(std::size_t primitive_count) { return auto_portfolio(primitive_count).front(); }

std::vector<Algorithm> auto_portfolio(std::size_t primitive_count) {
    if (primitive_count <= auto_optimal_max_primitives) return {Algorithm::optimal};
    if (primitive_count <= auto_merge_max_primitives)
        return {Algorithm::insertion_haber, Algorithm::insertion, Algorithm::split, Algorithm::merge, Algorithm::scale,
                Algorithm::binned};
    if (primitive_count <= auto_refine_each_max_primitives)
        return {Algorithm::scale, Algorithm::insertion_haber, Algorithm::insertion, Algorithm::split, Algorithm::binned};
    // Above, only the two cheapest unrefined trees are refined, and scale and insertion never built the cheapest
    // on 140 inputs of 33-200 primitives, nor the second cheapest on 47 of them (docs/treelets.md §4): they would
    // only cost time.
    if (primitive_count <= auto_insertion_max_primitives)
        return {Algorithm::insertion_haber, Algorithm::split, Algorithm::binned};
    if (primitive_count <= auto_portfolio_max_primitives) return {Algorithm::binned, Algorithm::split};
    return {Algorithm::binned};
}

}  // namespace hbvh
