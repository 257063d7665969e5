// SPDX-License-Identifier: MIT
#include "hbvh/builders/auto.hpp"

#include <optional>
#include <string>

#include "guarded_build.hpp"
#include "report_text.hpp"
#include "treelet_fit_cache.hpp"
#include "hbvh/builders/build.hpp"
#include "hbvh/tree/stats.hpp"

namespace hbvh {
namespace {

/// `auto`: every member of auto_portfolio(n) builds a tree and the cheapest under Eq. 2 (first in the list
/// on ties) wins. Up to auto_refine_each_max_primitives every member's tree is refined before the
/// comparison (refinement from different starts ends in different local optima, docs/treelets.md §3);
/// above, up to auto_refine_max_primitives, only the winner is.
Result<Bvh> auto_tree(std::span<const Primitive> primitives, const BuildContext& context, const AutoOptions& options) {
    const std::vector<Algorithm> members = auto_portfolio(primitives.size());
    const bool refine_any = members.front() != Algorithm::optimal &&
                            (options.refine_always || primitives.size() <= auto_refine_max_primitives);
    const bool refine_each = refine_any && primitives.size() <= auto_refine_each_max_primitives;
    std::optional<Bvh> best;
    BuildReport best_report;
    TreeletReport best_treelets;
    Algorithm winner = members.front();
    double best_cost = 0.0;
    std::string costs;
    const bool limited = context.has_deadline();
    std::string skipped;
    std::size_t done = 0;
    // The members' trees are over the same primitives and refined under the same policy, and their
    // treelets cover many of the same sets: one cache fits each set once for all of them.
    detail::TreeletFitCache fits(primitives.size());
    for (Algorithm member : members) {
        // Under a time limit the members share it: each gets what is left (and stops at its own checks), and
        // once nothing is left the rest are skipped (the first always runs, so there is a tree).
        if (best && limited && context.expired()) {
            skipped += (skipped.empty() ? "" : ", ") + std::string(to_string(member));
            continue;
        }
        BuildReport member_report;
        BuildContext member_context = context;
        member_context.report = context.report != nullptr ? &member_report : nullptr;
        member_context.progress = nullptr;  // auto reports per member instead
        Result<Bvh> built = build(primitives, member, member_context);
        if (!built) return built;
        Bvh tree = std::move(built.value());
        double member_cost = cost(tree, context.policy);
        if (!costs.empty()) costs += ", ";
        costs += std::string(to_string(member)) + " " + detail::format_cost(member_cost);
        TreeletReport treelets;
        if (refine_each) {
            tree = detail::refine_treelets_cached(tree, context.policy, treelets_within(context, options.treelets), fits,
                                                  &treelets);
            member_cost = treelets.cost_after;
            costs += " -> " + detail::format_cost(member_cost);
        }
        if (!best || member_cost < best_cost) {
            best = std::move(tree);
            best_cost = member_cost;
            best_report = std::move(member_report);
            best_treelets = treelets;
            winner = member;
        }
        context.report_progress(static_cast<double>(++done) / static_cast<double>(members.size() + 1));
    }
    if (refine_any && !refine_each)
        *best = detail::refine_treelets_cached(*best, context.policy, treelets_within(context, options.treelets), fits,
                                               &best_treelets);
    if (context.report != nullptr) {
        *context.report = std::move(best_report);
        if (members.size() > 1)
            context.report->notes.push_back("auto: " + std::to_string(primitives.size()) + " primitives, portfolio " +
                                            costs + (refine_each ? " (each refined)" : "") + "; kept " +
                                            std::string(to_string(winner)));
        else
            context.report->notes.push_back("auto: " + std::to_string(primitives.size()) + " primitives, built with " +
                                            std::string(to_string(winner)));
        if (!skipped.empty()) {
            context.report->notes.push_back("auto: time limit reached; skipped " + skipped);
            context.report->budget_hit = true;
        }
        if (refine_any) note_treelets(*context.report, best_treelets);
    }
    return Result<Bvh>(std::move(*best));
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

Algorithm auto_choice(std::size_t primitive_count) { return auto_portfolio(primitive_count).front(); }

std::vector<Algorithm> auto_portfolio(std::size_t primitive_count) {
    if (primitive_count <= auto_optimal_max_primitives) return {Algorithm::optimal};
    if (primitive_count <= auto_exact_max_primitives)
        return {Algorithm::bnb_exact, Algorithm::insertion_haber, Algorithm::insertion, Algorithm::split,
                Algorithm::merge, Algorithm::scale, Algorithm::binned};
    if (primitive_count <= auto_insertion_max_primitives)
        return {Algorithm::scale, Algorithm::insertion_haber, Algorithm::insertion, Algorithm::split, Algorithm::binned};
    if (primitive_count <= auto_portfolio_max_primitives) return {Algorithm::binned, Algorithm::split};
    return {Algorithm::binned};
}

}  // namespace hbvh
