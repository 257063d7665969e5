// SPDX-License-Identifier: MIT
// build_optimal: the subset DP of optimal_dp.cpp over fit_best's volume of every subset of the primitives, the
// volumes fitted on demand (docs/solver.md §2).
#include "hbvh/builders/optimal.hpp"
#include "optimal_plan.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <utility>

#include "guarded_build.hpp"
#include "hbvh/builders/bnb_exact.hpp"
#include "hbvh/fit/fit.hpp"
#include "treelet_bounds.hpp"

namespace hbvh {
namespace {

/// Fits on demand: the first round fits this fraction of all subsets (the unfitted ones through which the
/// cheapest trees over the current volumes pass), and each further round this factor times as many: a DP round
/// at 17 primitives costs about what 10 000 fits do, so few large rounds beat many small ones (measured in
/// docs/solver.md §2). A round that would fit half of the subsets still worth fitting or more fits them all.
constexpr double first_round_fraction = 0.1;
constexpr double round_growth = 3.0;
/// The share of the progress bar the bounds take (it counts subsets: the fits take the rest).
constexpr double bounds_share = 0.1;

/// The bits of `mask`, ascending: the covered primitives' input indices.
std::vector<std::uint32_t> members_of(std::uint32_t mask) {
    std::vector<std::uint32_t> out;
    for (std::uint32_t m = mask; m != 0; m &= m - 1u) out.push_back(static_cast<std::uint32_t>(std::countr_zero(m)));
    return out;
}

/// A lower bound of the weighted volume of every subset of two or more primitives (treelet_bounds.hpp), made
/// a size at a time from the bound of the subset without its lowest member and that member's: each size's in
/// parallel, each entry depending on its subset only. Only the previous size's hull points are kept.
std::vector<double> subset_bounds(std::span<const Primitive> primitives, std::uint32_t count, double scale,
                                  const std::vector<std::vector<std::uint32_t>>& by_size,
                                  const detail::Checkpoint& checkpoint) {
    const std::uint32_t subsets = 1u << count;
    std::vector<double> bound(subsets, 0.0);
    std::vector<detail::SetBound> made(subsets);
    for (std::uint32_t i = 0; i < count; ++i) {
        const std::uint32_t single[] = {i};
        made[1u << i] = detail::bound_set(primitives, single, scale);
    }
    for (std::uint32_t size = 2; size <= count; ++size) {
        // Progress counts subsets: the bounds are the first tenth of it (the fits and the DP rounds the rest).
        checkpoint.step(bounds_share * subsets * (size - 1) / count);
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, by_size[size].size(), 64),
                          [&](const tbb::blocked_range<std::size_t>& range) {
                              for (std::size_t j = range.begin(); j != range.end(); ++j) {
                                  const std::uint32_t mask = by_size[size][j];
                                  const std::uint32_t rest = mask & (mask - 1u);
                                  const std::uint32_t lowest = mask & ~rest;
                                  const std::uint32_t lowest_index[] = {
                                      static_cast<std::uint32_t>(std::countr_zero(lowest))};
                                  made[mask] = detail::bound_union(primitives, made[rest], members_of(rest),
                                                                   made[lowest], lowest_index, scale);
                                  bound[mask] = made[mask].bound;
                              }
                          });
        if (size > 2)  // the previous size's points are no longer needed (singletons are kept)
            for (std::uint32_t mask : by_size[size - 1]) made[mask] = {};
    }
    return bound;
}

/// The subsets the next round fits: of the unfitted ones through which a tree can cost at most `upper` (the
/// cheapest fitted tree known; through the others every tree costs more, so they are never needed), the `wanted`
/// cheapest by the cheapest tree through them under the current volumes (tables.best + the outside cost; ties by
/// mask), or all of them where that is at least half; and the plan's unfitted groups. Ascending.
std::vector<std::uint32_t> next_fits(const detail::SubsetTables& tables, std::span<const double> volume,
                                     const std::vector<std::vector<std::uint32_t>>& by_size,
                                     const std::vector<std::optional<BoundingVolume>>& fitted,
                                     const OptimalPlan& plan, double upper, std::size_t wanted) {
    std::vector<std::pair<double, std::uint32_t>> ranked;
    for (std::size_t size = 2; size < by_size.size(); ++size)
        for (std::uint32_t mask : by_size[size])
            if (!fitted[mask]) ranked.emplace_back(0.0, mask);
    if (std::isfinite(upper) || 2 * wanted < ranked.size()) {
        const std::vector<double> outside = detail::cost_outside(tables, volume);
        for (auto& [through, mask] : ranked) through = tables.best[mask] + outside[mask];
        std::erase_if(ranked, [&](const auto& entry) { return entry.first > upper; });
        if (2 * wanted < ranked.size()) {
            std::nth_element(ranked.begin(), ranked.begin() + static_cast<std::ptrdiff_t>(wanted), ranked.end());
            ranked.resize(wanted);
        }
    }
    std::vector<std::uint32_t> out;
    for (const auto& entry : ranked) out.push_back(entry.second);
    for (const OptimalGroup& group : plan.groups)  // the cheapest tree runs through them, but ties may hide them
        if (!fitted[group.covered]) out.push_back(group.covered);
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
}

Result<Bvh> optimal_tree(std::span<const Primitive> primitives, const BuildContext& context, std::uint32_t limit,
                         const detail::Checkpoint& checkpoint);

}  // namespace

Result<Bvh> build_optimal(std::span<const Primitive> primitives, const BuildContext& context,
                          const OptimalOptions& options) {
    const std::uint32_t limit = std::min(options.max_primitives, optimal_hard_limit);
    if (primitives.size() > limit && options.fall_back) {
        // Documented refusal of the DP, but a tree all the same (docs/solver.md §2).
        Result<Bvh> fallback = build_bnb_exact(primitives, context);
        if (fallback && context.report != nullptr) {
            context.report->lower_bound = 0.0;
            context.report->built_by = "bnb-exact";
            context.report->substitution = "optimal: " + std::to_string(primitives.size()) +
                                           " primitives exceed its limit of " + std::to_string(limit) +
                                           "; built bnb-exact instead (not proven optimal)";
            context.report->notes.push_back(context.report->substitution);
        }
        return fallback;
    }
    const double subsets = std::ldexp(1.0, static_cast<int>(std::min<std::size_t>(primitives.size(), 30)));
    return detail::guarded_build(primitives, context, "optimal", subsets, [&](const detail::Checkpoint& checkpoint) {
        return optimal_tree(primitives, context, limit, checkpoint);
    });
}

namespace {

Result<Bvh> optimal_tree(std::span<const Primitive> primitives, const BuildContext& context, std::uint32_t limit,
                         const detail::Checkpoint& checkpoint) {
    const auto start = std::chrono::steady_clock::now();
    const VolumePolicy& policy = context.policy;
    BuildReport* report = context.report;
    if (primitives.size() > limit)
        return Error{"the optimal builder handles at most " + std::to_string(limit) + " primitives, got " +
                     std::to_string(primitives.size()) + " (its subset DP is exponential; see docs/solver.md)"};
    const auto count = static_cast<std::uint32_t>(primitives.size());
    TreeAssembler assembler(primitives);
    std::vector<std::uint32_t> leaves(count);
    for (std::uint32_t i = 0; i < count; ++i) leaves[i] = assembler.add_leaf(i);
    if (count == 1) return std::move(assembler).finish(leaves.front());

    const std::uint32_t subsets = 1u << count;
    const std::vector<std::vector<std::uint32_t>> by_size = detail::masks_by_size(count);
    std::vector<double> volume(subsets, 0.0);
    std::vector<std::optional<BoundingVolume>> fitted(subsets);
    std::uint64_t fits = 0, solves = 0;
    // Where boxes or capsules are allowed a fit costs far more than a bound: subsets are fitted on demand.
    const bool on_demand = policy.is_allowed(BvType::obb) || policy.is_allowed(BvType::capsule);
    const auto fitting_progress = [&](std::uint64_t fitted_so_far) {  // in subsets, after the bounds' share
        const double share = on_demand ? bounds_share : 0.0;
        return subsets * (share + (1.0 - share) * static_cast<double>(fitted_so_far) / subsets);
    };
    // fit_best over the primitives of each of `masks`, with FitInput over them in input order (as two-level
    // does), in parallel: each entry depends on its subset only, so nothing depends on the thread count.
    const auto fit_masks = [&](std::span<const std::uint32_t> masks) {
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, masks.size(), 16),
                          [&](const tbb::blocked_range<std::size_t>& range) {
                              // approximate: blocks finish in any order
                              checkpoint.step(fitting_progress(fits + range.begin()));
                              for (std::size_t j = range.begin(); j != range.end(); ++j) {
                                  FitInput input;
                                  for (std::uint32_t i : members_of(masks[j])) input.add(primitives[i].volume);
                                  fitted[masks[j]] = fit_best(input.spheres, policy, input.hint_axes);
                                  volume[masks[j]] = policy.weighted_volume(*fitted[masks[j]]);
                              }
                          });
        fits += masks.size();
    };

    // The subset volumes. Fitted on demand, every subset stands in by a lower bound of its weighted volume until
    // it is fitted, and each round fits the unfitted subsets the cheapest trees pass through, until the DP's
    // optimum uses fitted subsets only. That optimum is the optimum over all fits (every other tree costs at
    // least its bounds), so the tree is the one of fitting every subset, up to a choice between trees of exactly
    // equal cost.
    if (on_demand) {
        volume = subset_bounds(primitives, count, detail::bound_scale(policy), by_size, checkpoint);
    } else {
        std::vector<std::uint32_t> all;
        for (std::uint32_t size = 2; size <= count; ++size)
            all.insert(all.end(), by_size[size].begin(), by_size[size].end());
        fit_masks(all);
    }
    double wanted = first_round_fraction * static_cast<double>(subsets);
    double upper = std::numeric_limits<double>::infinity();
    OptimalPlan plan;
    for (;;) {
        checkpoint.step(fitting_progress(fits));
        const detail::SubsetTables tables = detail::solve_subsets(count, volume);
        ++solves;
        plan = detail::plan_of(tables);
        const bool complete = std::all_of(plan.groups.begin(), plan.groups.end(),
                                          [&](const OptimalGroup& group) { return fitted[group.covered].has_value(); });
        if (complete) break;
        if (fits > 0) {
            // The cheapest tree of fitted subsets alone (the last plan's tree is one: its groups were fitted) is a
            // real tree, so what it costs bounds the optimum, and this round need not fit a subset through which
            // every tree costs more. On generated scenes it is already the optimum after the first round (the
            // rounds after it prove it). Not made before a second round: where the first round's fits suffice
            // (the bundled models), it would cost a DP for nothing.
            std::vector<double> fitted_only(volume);
            for (std::uint32_t mask = 0; mask < subsets; ++mask)
                if (std::popcount(mask) > 1 && !fitted[mask])
                    fitted_only[mask] = std::numeric_limits<double>::infinity();
            upper = std::min(upper, detail::solve_subsets(count, fitted_only).best.back());
        }
        fit_masks(next_fits(tables, volume, by_size, fitted, plan, upper, static_cast<std::size_t>(wanted)));
        wanted *= round_growth;
    }

    checkpoint.step(static_cast<double>(subsets));
    // The tree the DP chose (children before parents for the assembler).
    std::vector<std::uint32_t> id_of(subsets, 0);
    for (std::uint32_t i = 0; i < count; ++i) id_of[1u << i] = leaves[i];
    for (auto it = plan.groups.rbegin(); it != plan.groups.rend(); ++it) {
        std::vector<std::uint32_t> children;
        for (std::uint32_t child : it->children) children.push_back(id_of[child]);
        id_of[it->covered] = assembler.add_group(children, std::move(*fitted[it->covered]));
    }
    if (report != nullptr) {
        LevelReport level;
        level.nodes = count;
        level.groups = static_cast<std::uint32_t>(plan.groups.size());
        level.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        report->levels.push_back(level);
        report->lower_bound = plan.cost;
        report->notes.push_back("optimal: subset DP over " + std::to_string(subsets - count - 1) + " subsets, " +
                                std::to_string(fits) + " of them fitted, " + std::to_string(solves) + " DP rounds");
    }
    return std::move(assembler).finish(id_of[subsets - 1u]);
}

}  // namespace
}  // namespace hbvh
