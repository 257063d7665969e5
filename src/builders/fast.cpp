// SPDX-License-Identifier: MIT
// fast: binned's tree with its cheap fits, re-arranged by treelets priced with cheap fits on small objects, then
// fit_best on the nodes that weigh most in Eq. 2.
#include "hbvh/builders/fast.hpp"

#include <algorithm>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <tbb/parallel_for.h>
#include <tbb/task_group.h>

#include "guarded_build.hpp"
#include "treelet_fit_cache.hpp"
#include "../tree/collapse.hpp"
#include "hbvh/builders/binned.hpp"
#include "hbvh/builders/build.hpp"
#include "hbvh/fit/fit.hpp"

namespace hbvh {
namespace {

/// binned without its three slow steps for small inputs: the per-side fits of its cuts (estimate sweeps),
/// fit_best on every kept node and split's tree beside its own. What is left is the box-priced cuts (the root's
/// chosen by a look-ahead over `lookahead_candidates` cuts), the collapse and one cheap fit a node.
/// Where the treelet sweep follows, no node gets more children than a treelet has units: a wider node's
/// children could never be re-grouped (on the duplo brick, an 8-child node kept the tree at 1.11x auto's cost;
/// at most 5 children, 1.05x; no other object of docs/fast.md changed).
BinnedOptions cheap_binned(std::uint32_t max_children, std::uint32_t lookahead_candidates) {
    BinnedOptions options;
    options.lookahead_depth = lookahead_candidates > 0 ? 1 : 0;
    options.lookahead_candidates = lookahead_candidates;
    options.estimate_sweep_up_to = 0;
    options.exact_fit_all_up_to = 0;
    options.max_children = max_children;
    options.guarantee_split_up_to = 0;
    return options;
}

/// Up to this many primitives the finished tree goes through the exact collapse (its table is O(nodes x depth)).
constexpr std::size_t collapse_max_primitives = 2000;

/// Primitives below each node (nodes are breadth-first, so children come after their parent).
std::vector<std::uint32_t> primitive_counts(const Bvh& bvh) {
    std::vector<std::uint32_t> counts(bvh.nodes.size(), 0);
    for (std::size_t i = bvh.nodes.size(); i-- > 0;) {
        const Node& node = bvh.nodes[i];
        if (node.is_leaf()) counts[i] = 1;
        for (std::uint32_t c = node.first_child; c < node.first_child + node.child_count; ++c) counts[i] += counts[c];
    }
    return counts;
}

/// The `count` inner nodes over at most `max_primitives` primitives with the largest children x weighted volume
/// (their Eq. 2 terms), largest first (ties: the lower index).
std::vector<std::uint32_t> heaviest_inner_nodes(const Bvh& bvh, const VolumePolicy& policy, std::uint32_t count,
                                                std::uint32_t max_primitives) {
    const std::vector<std::uint32_t> below = primitive_counts(bvh);
    std::vector<std::pair<double, std::uint32_t>> terms;
    for (std::uint32_t i = 0; i < bvh.nodes.size(); ++i) {
        const Node& node = bvh.nodes[i];
        if (!node.is_leaf() && below[i] <= max_primitives)
            terms.emplace_back(node.child_count * policy.weighted_volume(node.volume), i);
    }
    const std::size_t keep = std::min<std::size_t>(count, terms.size());
    std::partial_sort(terms.begin(), terms.begin() + static_cast<std::ptrdiff_t>(keep), terms.end(),
                      [](const auto& a, const auto& b) { return a.first > b.first || (a.first == b.first && a.second < b.second); });
    std::vector<std::uint32_t> nodes;
    for (std::size_t k = 0; k < keep; ++k) nodes.push_back(terms[k].second);
    return nodes;
}

/// fit_best over `primitives` (in input order, as covered_primitives lists them).
BoundingVolume best_fit_of(std::span<const Primitive> primitives, std::span<const std::uint32_t> indices,
                           const VolumePolicy& policy) {
    FitInput input;
    for (const std::uint32_t p : indices) input.add(primitives[p].volume);
    return fit_best(input.spheres, policy, input.hint_axes);
}

/// fit_best over the primitives below `node`.
BoundingVolume best_fit_below(const Bvh& bvh, std::uint32_t node, const VolumePolicy& policy) {
    return best_fit_of(bvh.primitives, covered_primitives(bvh, node), policy);
}

/// Waits for a task group however the scope is left (a task_group must not be destroyed with tasks running).
/// The normal path waits explicitly, so that a task's exception reaches the caller; here, on the way out of an
/// early return or an exception, it is dropped.
struct WaitOnExit {
    tbb::task_group& tasks;
    ~WaitOnExit() {
        try {
            tasks.wait();
        } catch (...) {
        }
    }
};

}  // namespace

Result<Bvh> build_fast(std::span<const Primitive> primitives, const BuildContext& context, const FastOptions& options) {
    // binned reports its progress as the first half, the refits the second.
    BuildContext first_step = context;
    if (context.progress) first_step.progress = [&context](double fraction) { context.report_progress(0.5 * fraction); };
    const bool sweep = options.treelet_units >= 3 && primitives.size() <= options.treelet_max_primitives;
    // The root covers every primitive whatever the tree's shape, and it nearly always weighs most, so its refit
    // starts now on another core, beside the cheap build and the sweep, instead of after them (a tenth to a
    // fifth of the preset's time on 13-54 primitives, docs/fast.md). Used only if the root is among the
    // heaviest nodes (it is an inner node from 2 primitives on, and within the size cap here).
    std::optional<BoundingVolume> root_refit;
    // Sets of primitives refitted in the background during the sweep (below), with their fits. Declared before
    // the task group, so that its tasks are waited for before these go away.
    std::vector<std::pair<std::vector<std::uint32_t>, std::optional<BoundingVolume>>> early;
    tbb::task_group background;
    const WaitOnExit wait_for_background{background};
    if (options.exact_fits > 0 && primitives.size() >= 2 && primitives.size() <= options.exact_fit_max_primitives)
        background.run([&] {
            std::vector<std::uint32_t> all(primitives.size());
            for (std::uint32_t i = 0; i < all.size(); ++i) all[i] = i;
            root_refit = best_fit_of(primitives, all, context.policy);
        });
    Result<Bvh> built =
        build_binned(primitives, first_step, cheap_binned(sweep ? std::min(options.treelet_units, BinnedOptions{}.max_children)
                                                                : BinnedOptions{}.max_children, options.lookahead_candidates));
    if (!built || context.expired()) return built;
    // The heaviest nodes below the root of the cheap tree are refitted in the background too, during the sweep: a
    // refit depends on its set of primitives only, and the sweep re-arranges treelets of a few units, so such a
    // set is often still a heavy node afterwards. On the peers' 17 objects of up to 64 primitives the preset took
    // up to a quarter less time (the cannon 1 % more); where the sweep re-forms that node (generated-30-7) the
    // background fit takes a core from the sweep for nothing, about 10 % more (docs/fast.md).
    if (sweep && options.exact_fits > 1) {
        for (const std::uint32_t node :
             heaviest_inner_nodes(*built, context.policy, options.exact_fits, options.exact_fit_max_primitives))
            if (node != 0) early.emplace_back(covered_primitives(*built, node), std::nullopt);
        for (auto& [set, fit] : early)
            background.run([&, &set = set, &fit = fit] { fit = best_fit_of(primitives, set, context.policy); });
    }
    // binned's cuts are priced by boxes and never revisited; on small objects that topology, not the fits, is
    // most of the gap to auto (docs/fast.md). Treelets priced by the cheap fitter close much of it for a few
    // hundred microseconds, where fit_best's pricing (auto's) would cost a hundred times more.
    if (sweep) {
        detail::TreeletFitCache quick_fits(built->primitives.size(), detail::TreeletFitter::quick);
        TreeletOptions treelets;
        treelets.max_units = options.treelet_units;
        treelets.max_passes = 1;  // a second changed no cost by more than 0.01 % with 4 units (docs/fast.md)
        TreeletReport report;
        *built = detail::refine_treelets_cached(*built, context.policy, treelets_within(context, treelets), quick_fits,
                                                &report);
        if (context.report != nullptr)
            context.report->notes.push_back("fast: " + std::to_string(report.treelets) + " treelets priced by quick fits, " +
                                            std::to_string(report.replaced) + " re-arranged");
    }
    if (context.expired() || options.exact_fits == 0) return detail::check_build_output(std::move(built), "fast");
    Bvh& bvh = *built;
    const std::vector<std::uint32_t> heaviest =
        heaviest_inner_nodes(bvh, context.policy, options.exact_fits, options.exact_fit_max_primitives);
    // Each refit reads the tree's shape and primitives only, so they run in parallel and the result does not
    // depend on the thread count (without a deadline; with one, a refit that would start after it is skipped).
    std::vector<std::optional<BoundingVolume>> refits(heaviest.size());
    std::vector<std::vector<std::uint32_t>> sets(heaviest.size());
    std::vector<std::size_t> fresh;  // the heaviest nodes whose set no background refit covers
    for (std::size_t k = 0; k < heaviest.size(); ++k) {
        if (heaviest[k] == 0) continue;
        sets[k] = covered_primitives(bvh, heaviest[k]);
        if (std::none_of(early.begin(), early.end(), [&](const auto& e) { return e.first == sets[k]; })) fresh.push_back(k);
    }
    tbb::parallel_for(std::size_t{0}, fresh.size(), [&](std::size_t i) {
        if (!context.expired()) refits[fresh[i]] = best_fit_of(bvh.primitives, sets[fresh[i]], context.policy);
    });
    background.wait();
    for (std::size_t k = 0; k < heaviest.size(); ++k) {
        if (heaviest[k] == 0) {
            refits[k] = std::move(root_refit);
            continue;
        }
        for (auto& [set, fit] : early)
            if (set == sets[k] && fit) refits[k] = fit;
    }
    std::size_t kept = 0;
    for (std::size_t k = 0; k < heaviest.size(); ++k) {
        if (!refits[k]) continue;
        Node& node = bvh.nodes[heaviest[k]];
        // fit_best tries more frames than the cheap fit but not all of them (DiTO's frames are binned's, the
        // principal frame of the centres too), so it can come out larger: keep whichever is cheaper.
        if (context.policy.weighted_volume(*refits[k]) < context.policy.weighted_volume(node.volume)) {
            node.volume = std::move(*refits[k]);
            ++kept;
        }
    }
    if (context.report != nullptr)
        context.report->notes.push_back("fast: fit_best on the " + std::to_string(heaviest.size()) +
                                        " heaviest inner nodes, cheaper on " + std::to_string(kept));
    if (context.expired()) context.note_deadline("fast: refits after the deadline skipped");
    // As auto does: dissolve the nodes whose removal lowers Eq. 2 (exact, O(nodes x depth)), where the tree is
    // small enough for its table.
    if (options.collapse && primitives.size() <= collapse_max_primitives) {
        const std::size_t nodes = bvh.nodes.size();
        bvh = detail::collapse_optimally(bvh, context.policy);
        if (context.report != nullptr && bvh.nodes.size() < nodes)
            context.report->notes.push_back("fast: the exact collapse dissolved " + std::to_string(nodes - bvh.nodes.size()) +
                                            " nodes");
    }
    context.report_progress(1.0);
    return detail::check_build_output(std::move(built), "fast");
}

}  // namespace hbvh
