// SPDX-License-Identifier: MIT
// fast: binned's tree with its cheap fits, re-arranged by treelets priced with cheap fits on small objects, then
// fit_best on the nodes that weigh most in Eq. 2.
#include "hbvh/builders/fast.hpp"

#include <algorithm>
#include <deque>
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

/// fit_best refits started early on the second core: a refit depends on its set of primitives only, so one made
/// before the tree is final serves any node of the final tree over the same set (the trees are those of fitting
/// last). Sets are added before any is read; the destructor waits for the tasks.
class EarlyRefits {
public:
    EarlyRefits(std::span<const Primitive> primitives, const VolumePolicy& policy) : primitives_(primitives), policy_(policy) {}
    EarlyRefits(const EarlyRefits&) = delete;
    EarlyRefits& operator=(const EarlyRefits&) = delete;
    ~EarlyRefits() {
        try {
            tasks_.wait();
        } catch (...) {  // only on the way out of an early return or an exception; take() reports a task's failure
        }
    }

    /// Starts fit_best over `set` (input indices, ascending).
    void start(std::vector<std::uint32_t> set) {
        Refit& refit = refits_.emplace_back(Refit{std::move(set), std::nullopt});
        tasks_.run([this, &refit] { refit.fit = best_fit_of(primitives_, refit.set, policy_); });
    }
    [[nodiscard]] bool started(std::span<const std::uint32_t> set) const {
        return std::any_of(refits_.begin(), refits_.end(), [&](const Refit& r) { return std::ranges::equal(r.set, set); });
    }
    /// The fit of `set`, once every started refit is done; nothing if none was started for it.
    [[nodiscard]] std::optional<BoundingVolume> take(std::span<const std::uint32_t> set) {
        tasks_.wait();
        for (Refit& refit : refits_)
            if (std::ranges::equal(refit.set, set)) return refit.fit;
        return std::nullopt;
    }

private:
    struct Refit {
        std::vector<std::uint32_t> set;
        std::optional<BoundingVolume> fit;
    };
    std::span<const Primitive> primitives_;
    const VolumePolicy& policy_;
    std::deque<Refit> refits_;  // a deque: adding one moves none, so the running tasks' references stay valid
    tbb::task_group tasks_;
};

/// Refits the `exact_fits` heaviest inner nodes (over at most `max_primitives` primitives) with fit_best, taking
/// the early refits where their sets agree and fitting the rest in parallel now; each new volume is kept only
/// where it is cheaper. Returns (nodes refitted, nodes made cheaper).
std::pair<std::size_t, std::size_t> refit_heaviest(Bvh& bvh, const BuildContext& context, std::uint32_t exact_fits,
                                                   std::uint32_t max_primitives, EarlyRefits& early) {
    const std::vector<std::uint32_t> heaviest = heaviest_inner_nodes(bvh, context.policy, exact_fits, max_primitives);
    std::vector<std::vector<std::uint32_t>> sets(heaviest.size());
    std::vector<std::size_t> now;  // the nodes whose set no early refit covers
    for (std::size_t k = 0; k < heaviest.size(); ++k) {
        sets[k] = covered_primitives(bvh, heaviest[k]);
        if (!early.started(sets[k])) now.push_back(k);
    }
    // Each refit reads its set only, so they run in parallel and the result does not depend on the thread count
    // (without a deadline; with one, a refit that would start after it is skipped).
    std::vector<std::optional<BoundingVolume>> refits(heaviest.size());
    tbb::parallel_for(std::size_t{0}, now.size(), [&](std::size_t i) {
        if (!context.expired()) refits[now[i]] = best_fit_of(bvh.primitives, sets[now[i]], context.policy);
    });
    std::size_t kept = 0;
    for (std::size_t k = 0; k < heaviest.size(); ++k) {
        if (!refits[k]) refits[k] = early.take(sets[k]);
        if (!refits[k]) continue;
        Node& node = bvh.nodes[heaviest[k]];
        // fit_best tries more frames than the cheap fit but not all of them (DiTO's frames are binned's, the
        // principal frame of the centres too), so it can come out larger: keep whichever is cheaper.
        if (context.policy.weighted_volume(*refits[k]) < context.policy.weighted_volume(node.volume)) {
            node.volume = std::move(*refits[k]);
            ++kept;
        }
    }
    return {heaviest.size(), kept};
}

}  // namespace

Result<Bvh> build_fast(std::span<const Primitive> primitives, const BuildContext& context, const FastOptions& options) {
    // binned reports its progress as the first half, the refits the second.
    BuildContext first_step = context;
    if (context.progress) first_step.progress = [&context](double fraction) { context.report_progress(0.5 * fraction); };
    const bool sweep = options.treelet_units >= 3 && primitives.size() <= options.treelet_max_primitives;
    const bool refit = options.exact_fits > 0 && primitives.size() >= 2;
    // The root covers every primitive whatever the tree's shape, and it nearly always weighs most, so its refit
    // starts now, beside the cheap build and the sweep, instead of after them (a tenth to a fifth of the preset's
    // time on 13-54 primitives, docs/fast.md). It is an inner node from 2 primitives on.
    EarlyRefits early(primitives, context.policy);
    if (refit && primitives.size() <= options.exact_fit_max_primitives) {
        // binned's guard checks the input too, but only after this refit has started on it (a NaN weight made it
        // recurse without end): checked here first. Larger inputs start no refit, and binned checks them once.
        if (Status input = detail::check_build_input(primitives, context.policy); !input) return input.error();
        std::vector<std::uint32_t> all(primitives.size());
        for (std::uint32_t i = 0; i < all.size(); ++i) all[i] = i;
        early.start(std::move(all));
    }
    const std::size_t notes_before = context.report != nullptr ? context.report->notes.size() : 0;
    const bool stopped_before = context.report != nullptr && !context.report->time_limit.empty();
    Result<Bvh> built =
        build_binned(primitives, first_step, cheap_binned(sweep ? std::min(options.treelet_units, BinnedOptions{}.max_children)
                                                                : BinnedOptions{}.max_children, options.lookahead_candidates));
    // binned's notes ("binned: time limit reached ...") are the preset's first step's: a user who asked for fast
    // reads fast's name first, in the notes and in the time-limit line that the CLI and Python warn with.
    if (context.report != nullptr) {
        for (std::size_t i = notes_before; i < context.report->notes.size(); ++i)
            context.report->notes[i].insert(0, "fast: the first step, ");
        if (!stopped_before && !context.report->time_limit.empty())
            context.report->time_limit.insert(0, "fast: the first step, ");
    }
    if (!built || context.expired()) return built;
    Bvh& bvh = *built;
    // binned's cuts are priced by boxes and never revisited; on small objects that topology, not the fits, is
    // most of the gap to auto (docs/fast.md). Treelets priced by the cheap fitter close much of it for a few
    // hundred microseconds, where fit_best's pricing (auto's) would cost a hundred times more.
    if (sweep) {
        // The heaviest nodes below the root of the cheap tree are refitted during the sweep: it re-arranges
        // treelets of a few units, so such a set is often still a heavy node afterwards. On the peers' 17 objects
        // of up to 64 primitives the preset took up to a quarter less time (the cannon 1 % more); where the sweep
        // re-forms that node (generated-30-7) the early fit takes a core from the sweep for nothing, about 10 %
        // more (docs/fast.md).
        if (refit && options.exact_fits > 1)
            for (const std::uint32_t node : heaviest_inner_nodes(bvh, context.policy, options.exact_fits, options.exact_fit_max_primitives))
                if (node != 0) early.start(covered_primitives(bvh, node));
        detail::TreeletFitCache quick_fits(bvh.primitives.size(), detail::TreeletFitter::quick);
        TreeletOptions treelets;
        treelets.max_units = options.treelet_units;
        treelets.max_passes = 1;  // a second changed no cost by more than 0.01 % with 4 units (docs/fast.md)
        TreeletReport report;
        bvh = detail::refine_treelets_cached(bvh, context.policy, treelets_within(context, treelets), quick_fits, &report);
        if (context.report != nullptr)
            context.report->notes.push_back("fast: " + std::to_string(report.treelets) + " treelets priced by quick fits, " +
                                            std::to_string(report.replaced) + " re-arranged");
    }
    if (refit && !context.expired()) {
        const auto [refitted, cheaper] =
            refit_heaviest(bvh, context, options.exact_fits, options.exact_fit_max_primitives, early);
        if (context.report != nullptr)
            context.report->notes.push_back("fast: fit_best on the " + std::to_string(refitted) +
                                            " heaviest inner nodes, cheaper on " + std::to_string(cheaper));
        if (context.expired()) context.note_deadline("fast: refits after the deadline skipped");
    }
    // As auto does: dissolve the nodes whose removal lowers Eq. 2 (exact, O(nodes x depth)), where the tree is
    // small enough for its table.
    if (options.collapse && primitives.size() <= detail::collapse_max_primitives) {
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
